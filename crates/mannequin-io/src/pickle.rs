//! A reader for Python pickles (protocols 0–5) that builds a tree of values instead of Python
//! objects, so the `.pkl` model files of this field load without Python. It imports and calls
//! nothing: a class or function stays a name ([`Value::Global`]), and applying it (REDUCE,
//! NEWOBJ, INST/OBJ, then BUILD) is recorded as a [`Value::Object`] for the caller to interpret
//! (`pickle_arrays.rs` knows NumPy, SciPy and chumpy).
//!
//! Values live in one arena and refer to each other by index, so the memo shares them as Python
//! does: a list appended to, or an object built, after it was memoised is seen changed through
//! every reference. Every opcode adds at most one value, one memo entry or one stack slot, and
//! every length is checked against the bytes left, so memory stays proportional to the input.

use std::collections::HashMap;

use crate::error::PickleError;

/// An index into [`Pickle`]'s values.
pub type ValueId = usize;

#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    None,
    Bool(bool),
    Int(i64),
    Float(f64),
    /// `bytes`, `bytearray`, and Python 2 `str` (which is how Python 2 pickles hold array data).
    Bytes(Vec<u8>),
    Str(String),
    Tuple(Vec<ValueId>),
    /// Lists, and sets (their order is the pickle's).
    List(Vec<ValueId>),
    /// Entries in insertion order.
    Dict(Vec<(ValueId, ValueId)>),
    Global {
        module: String,
        name: String,
    },
    /// `class(*args)` (`args` is a [`Value::Tuple`]), with `state` if BUILD followed.
    Object {
        class: ValueId,
        args: ValueId,
        state: Option<ValueId>,
    },
}

/// A parsed pickle: its values and the one the pickle returns.
#[derive(Debug, Clone)]
pub struct Pickle {
    values: Vec<Value>,
    root: ValueId,
}

impl Pickle {
    pub fn root(&self) -> ValueId {
        self.root
    }

    pub fn get(&self, id: ValueId) -> &Value {
        &self.values[id]
    }

    /// Runs the pickle's opcodes up to STOP.
    pub fn parse(bytes: &[u8]) -> Result<Self, PickleError> {
        Machine {
            bytes,
            pos: 0,
            values: Vec::new(),
            stack: Vec::new(),
            marks: Vec::new(),
            memo: HashMap::new(),
        }
        .run()
    }
}

struct Machine<'a> {
    bytes: &'a [u8],
    pos: usize,
    values: Vec<Value>,
    stack: Vec<ValueId>,
    /// Stack heights at each MARK.
    marks: Vec<usize>,
    memo: HashMap<u64, ValueId>,
}

impl<'a> Machine<'a> {
    fn fail<T>(&self, reason: impl Into<String>) -> Result<T, PickleError> {
        Err(PickleError { offset: self.pos, reason: reason.into() })
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], PickleError> {
        if self.bytes.len() - self.pos < n {
            return self.fail(format!("truncated: {n} bytes needed, {} left", self.bytes.len() - self.pos));
        }
        let start = self.pos;
        self.pos += n;
        Ok(&self.bytes[start..self.pos])
    }

    fn uint(&mut self, n: usize) -> Result<u64, PickleError> {
        Ok(self.take(n)?.iter().rev().fold(0u64, |v, &b| (v << 8) | b as u64))
    }

    /// A length field of `n` bytes, checked against the bytes left.
    fn len(&mut self, n: usize) -> Result<usize, PickleError> {
        let len = self.uint(n)?;
        match usize::try_from(len) {
            Ok(len) if len <= self.bytes.len() - self.pos => Ok(len),
            _ => self.fail(format!("length {len} runs past the end")),
        }
    }

    /// A text argument up to the next newline (protocol 0 opcodes).
    fn line(&mut self) -> Result<&'a str, PickleError> {
        let bytes = self.bytes;
        let rest = &bytes[self.pos..];
        let Some(end) = rest.iter().position(|&b| b == b'\n') else {
            return self.fail("truncated: unterminated text argument");
        };
        self.pos += end + 1;
        std::str::from_utf8(&rest[..end]).or_else(|_| self.fail("text argument is not UTF-8"))
    }

    fn push(&mut self, v: Value) -> ValueId {
        self.values.push(v);
        let id = self.values.len() - 1;
        self.stack.push(id);
        id
    }

    fn pop(&mut self) -> Result<ValueId, PickleError> {
        if self.stack.len() <= self.marks.last().copied().unwrap_or(0) {
            return self.fail("stack underflow");
        }
        Ok(self.stack.pop().expect("checked non-empty"))
    }

    fn top(&self) -> Result<ValueId, PickleError> {
        match self.stack.last() {
            Some(&id) if self.stack.len() > self.marks.last().copied().unwrap_or(0) => Ok(id),
            _ => self.fail("stack underflow"),
        }
    }

    /// The values pushed since the last MARK, which is removed.
    fn pop_mark(&mut self) -> Result<Vec<ValueId>, PickleError> {
        let Some(mark) = self.marks.pop() else {
            return self.fail("no MARK to pop to");
        };
        Ok(self.stack.split_off(mark))
    }

    fn pairs(&self, items: Vec<ValueId>) -> Result<Vec<(ValueId, ValueId)>, PickleError> {
        if !items.len().is_multiple_of(2) {
            return self.fail("odd number of items for a dict");
        }
        Ok(items.chunks_exact(2).map(|p| (p[0], p[1])).collect())
    }

    fn extend_list(&mut self, list: ValueId, items: Vec<ValueId>) -> Result<(), PickleError> {
        match &mut self.values[list] {
            Value::List(v) => {
                v.extend(items);
                Ok(())
            }
            _ => self.fail("APPEND/ADDITEMS to something that is not a list or set"),
        }
    }

    fn extend_dict(&mut self, dict: ValueId, items: Vec<(ValueId, ValueId)>) -> Result<(), PickleError> {
        match &mut self.values[dict] {
            Value::Dict(v) => {
                v.extend(items);
                Ok(())
            }
            _ => self.fail("SETITEM to something that is not a dict"),
        }
    }

    fn memo_put(&mut self, key: u64) -> Result<(), PickleError> {
        let top = self.top()?;
        self.memo.insert(key, top);
        Ok(())
    }

    fn memo_get(&mut self, key: u64) -> Result<(), PickleError> {
        match self.memo.get(&key) {
            Some(&id) => {
                self.stack.push(id);
                Ok(())
            }
            None => self.fail(format!("memo key {key} was never stored")),
        }
    }

    fn global(&mut self, module: String, name: String) {
        self.push(Value::Global { module, name });
    }

    /// Pushes `class(*args)`; `args` must be a tuple, and is referred to, not copied.
    fn object(&mut self, class: ValueId, args: ValueId) -> Result<(), PickleError> {
        if !matches!(self.values[args], Value::Tuple(_)) {
            return self.fail("arguments of REDUCE/NEWOBJ are not a tuple");
        }
        self.push(Value::Object { class, args, state: None });
        Ok(())
    }

    /// A new tuple value, off the stack.
    fn tuple(&mut self, items: Vec<ValueId>) -> ValueId {
        self.values.push(Value::Tuple(items));
        self.values.len() - 1
    }

    /// A little-endian two's-complement integer of up to 8 bytes (LONG1, LONG4).
    fn long(&mut self, n: usize) -> Result<(), PickleError> {
        if n > 8 {
            return self.fail(format!("a {n}-byte integer does not fit in 64 bits"));
        }
        let raw = self.uint(n)?;
        let shift = 64 - 8 * n as u32;
        let v = if n == 0 { 0 } else { ((raw << shift) as i64) >> shift };
        self.push(Value::Int(v));
        Ok(())
    }

    fn int_text(&mut self) -> Result<(), PickleError> {
        let text = self.line()?.trim_end_matches('L').to_string();
        let v = match text.as_str() {
            "00" => Value::Bool(false),
            "01" => Value::Bool(true),
            t => Value::Int(t.parse().or_else(|_| self.fail(format!("bad integer '{t}'")))?),
        };
        self.push(v);
        Ok(())
    }

    fn run(mut self) -> Result<Pickle, PickleError> {
        loop {
            let op = self.take(1)?[0];
            match op {
                0x80 => {
                    let proto = self.uint(1)?;
                    if proto > 5 {
                        return self.fail(format!("unsupported pickle protocol {proto}"));
                    }
                }
                0x95 => {
                    self.uint(8)?; // FRAME: a length hint only
                }
                b'.' => {
                    let root = self.pop()?;
                    return Ok(Pickle { values: self.values, root });
                }
                b'(' => self.marks.push(self.stack.len()),
                b'0' => {
                    self.pop()?;
                }
                b'1' => {
                    self.pop_mark()?;
                }
                b'2' => {
                    let top = self.top()?;
                    self.stack.push(top);
                }
                b'N' => {
                    self.push(Value::None);
                }
                0x88 | 0x89 => {
                    self.push(Value::Bool(op == 0x88));
                }
                b'I' | b'L' => self.int_text()?,
                b'J' => {
                    let v = self.uint(4)? as u32 as i32;
                    self.push(Value::Int(v.into()));
                }
                b'K' | b'M' => {
                    let v = self.uint(if op == b'K' { 1 } else { 2 })?;
                    self.push(Value::Int(v as i64));
                }
                0x8a => {
                    let n = self.len(1)?;
                    self.long(n)?;
                }
                0x8b => {
                    let n = self.len(4)?;
                    self.long(n)?;
                }
                b'F' => {
                    let t = self.line()?.to_string();
                    let v = t.trim().parse().or_else(|_| self.fail(format!("bad float '{t}'")))?;
                    self.push(Value::Float(v));
                }
                b'G' => {
                    let v = f64::from_be_bytes(self.take(8)?.try_into().expect("8 bytes"));
                    self.push(Value::Float(v));
                }
                b'S' => {
                    let t = self.line()?.to_string();
                    let Some(v) = unquote(&t) else { return self.fail(format!("bad quoted string {t:.40}")) };
                    self.push(Value::Bytes(v));
                }
                b'T' | b'U' | b'B' | b'C' | 0x8e | 0x96 => {
                    let n = self.len(match op {
                        b'U' | b'C' => 1,
                        0x8e | 0x96 => 8,
                        _ => 4,
                    })?;
                    let v = self.take(n)?.to_vec();
                    self.push(Value::Bytes(v));
                }
                b'V' => {
                    let t = self.line()?.to_string();
                    let Some(v) = raw_unicode_unescape(&t) else {
                        return self.fail(format!("bad unicode text {t:.40}"));
                    };
                    self.push(Value::Str(v));
                }
                b'X' | 0x8c | 0x8d => {
                    let n = self.len(match op {
                        0x8c => 1,
                        0x8d => 8,
                        _ => 4,
                    })?;
                    let raw = self.take(n)?;
                    let v = String::from_utf8(raw.to_vec()).or_else(|_| self.fail("string is not UTF-8"))?;
                    self.push(Value::Str(v));
                }
                b')' => {
                    self.push(Value::Tuple(Vec::new()));
                }
                b't' => {
                    let items = self.pop_mark()?;
                    self.push(Value::Tuple(items));
                }
                0x85..=0x87 => {
                    let n = (op - 0x84) as usize;
                    let mut items = (0..n).map(|_| self.pop()).collect::<Result<Vec<_>, _>>()?;
                    items.reverse();
                    self.push(Value::Tuple(items));
                }
                b']' | 0x8f => {
                    self.push(Value::List(Vec::new()));
                }
                b'l' | 0x91 => {
                    let items = self.pop_mark()?;
                    self.push(Value::List(items));
                }
                b'a' => {
                    let item = self.pop()?;
                    let list = self.top()?;
                    self.extend_list(list, vec![item])?;
                }
                b'e' | 0x90 => {
                    let items = self.pop_mark()?;
                    let list = self.top()?;
                    self.extend_list(list, items)?;
                }
                b'}' => {
                    self.push(Value::Dict(Vec::new()));
                }
                b'd' => {
                    let items = self.pop_mark()?;
                    let pairs = self.pairs(items)?;
                    self.push(Value::Dict(pairs));
                }
                b's' => {
                    let (value, key) = (self.pop()?, self.pop()?);
                    let dict = self.top()?;
                    self.extend_dict(dict, vec![(key, value)])?;
                }
                b'u' => {
                    let items = self.pop_mark()?;
                    let pairs = self.pairs(items)?;
                    let dict = self.top()?;
                    self.extend_dict(dict, pairs)?;
                }
                b'c' => {
                    let module = self.line()?.to_string();
                    let name = self.line()?.to_string();
                    self.global(module, name);
                }
                0x93 => {
                    let (name, module) = (self.pop()?, self.pop()?);
                    match (&self.values[module], &self.values[name]) {
                        (Value::Str(m), Value::Str(n)) => {
                            let (m, n) = (m.clone(), n.clone());
                            self.global(m, n);
                        }
                        _ => return self.fail("STACK_GLOBAL needs two strings"),
                    }
                }
                b'R' | 0x81 => {
                    let (args, class) = (self.pop()?, self.pop()?);
                    self.object(class, args)?;
                }
                0x92 => {
                    let (_kwargs, args, class) = (self.pop()?, self.pop()?, self.pop()?);
                    self.object(class, args)?;
                }
                b'i' => {
                    let (module, name) = (self.line()?.to_string(), self.line()?.to_string());
                    let items = self.pop_mark()?;
                    let args = self.tuple(items);
                    self.values.push(Value::Global { module, name });
                    self.object(self.values.len() - 1, args)?;
                }
                b'o' => {
                    let mut items = self.pop_mark()?;
                    if items.is_empty() {
                        return self.fail("OBJ without a class");
                    }
                    let class = items.remove(0);
                    let args = self.tuple(items);
                    self.object(class, args)?;
                }
                b'b' => {
                    let state = self.pop()?;
                    let target = self.top()?;
                    match &mut self.values[target] {
                        Value::Object { state: s, .. } => *s = Some(state),
                        _ => return self.fail("BUILD on something that is not an object"),
                    }
                }
                b'p' => {
                    let t = self.line()?.to_string();
                    let key = t.parse().or_else(|_| self.fail(format!("bad memo key '{t}'")))?;
                    self.memo_put(key)?;
                }
                b'q' | b'r' => {
                    let key = self.uint(if op == b'q' { 1 } else { 4 })?;
                    self.memo_put(key)?;
                }
                0x94 => {
                    let key = self.memo.len() as u64;
                    self.memo_put(key)?;
                }
                b'g' => {
                    let t = self.line()?.to_string();
                    let key = t.parse().or_else(|_| self.fail(format!("bad memo key '{t}'")))?;
                    self.memo_get(key)?;
                }
                b'h' | b'j' => {
                    let key = self.uint(if op == b'h' { 1 } else { 4 })?;
                    self.memo_get(key)?;
                }
                _ => {
                    self.pos -= 1;
                    return self.fail(format!(
                        "unsupported opcode 0x{op:02x} (persistent ids, extension codes and out-of-band buffers are not read)"
                    ));
                }
            }
        }
    }
}

/// The bytes of a Python 2 `repr` string literal (`'...'` or `"..."`), as STRING holds it.
fn unquote(text: &str) -> Option<Vec<u8>> {
    let q = text.chars().next().filter(|&c| c == '\'' || c == '"')?;
    let inner = text.strip_prefix(q)?.strip_suffix(q)?.as_bytes();
    let mut out = Vec::with_capacity(inner.len());
    let mut i = 0;
    while i < inner.len() {
        let b = inner[i];
        i += 1;
        if b != b'\\' {
            out.push(b);
            continue;
        }
        let e = *inner.get(i)?;
        i += 1;
        out.push(match e {
            b'n' => b'\n',
            b'r' => b'\r',
            b't' => b'\t',
            b'\\' | b'\'' | b'"' => e,
            b'x' => {
                let hex = std::str::from_utf8(inner.get(i..i + 2)?).ok()?;
                i += 2;
                u8::from_str_radix(hex, 16).ok()?
            }
            _ => return None,
        });
    }
    Some(out)
}

/// Python's `raw-unicode-escape`: `\uXXXX` and `\UXXXXXXXX` escapes, every other byte Latin-1.
fn raw_unicode_unescape(text: &str) -> Option<String> {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        let digits = match (c, chars.peek()) {
            ('\\', Some('u')) => 4,
            ('\\', Some('U')) => 8,
            _ => {
                out.push(c);
                continue;
            }
        };
        chars.next();
        let hex: String = chars.by_ref().take(digits).collect();
        if hex.len() != digits {
            return None;
        }
        out.push(char::from_u32(u32::from_str_radix(&hex, 16).ok()?)?);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text(p: &Pickle, id: ValueId) -> String {
        match p.get(id) {
            Value::Str(s) => s.clone(),
            Value::Bytes(b) => String::from_utf8_lossy(b).into_owned(),
            v => format!("{v:?}"),
        }
    }

    #[test]
    fn protocol_0_dict_with_memoised_list() {
        // Python 3's pickle.dumps({'a': [1, 2.5, 'x'], 'b': None}, protocol=0), and Python 2's
        // form of it (byte strings).
        for bytes in [
            &b"(dp0\nVa\np1\n(lp2\nI1\naF2.5\naVx\np3\nasVb\np4\nNs."[..],
            &b"(dp0\nS'a'\np1\n(lp2\nI1\naF2.5\naS'x'\np3\nasS'b'\np4\nNs."[..],
        ] {
            check_protocol_0_dict(&Pickle::parse(bytes).unwrap());
        }
    }

    fn check_protocol_0_dict(p: &Pickle) {
        let Value::Dict(entries) = p.get(p.root()) else { panic!("{:?}", p.get(p.root())) };
        assert_eq!(entries.len(), 2);
        assert_eq!(text(p, entries[0].0), "a");
        let Value::List(items) = p.get(entries[0].1) else { panic!() };
        assert_eq!(p.get(items[0]), &Value::Int(1));
        assert_eq!(p.get(items[1]), &Value::Float(2.5));
        assert_eq!(text(p, items[2]), "x");
        assert_eq!(p.get(entries[1].1), &Value::None);
    }

    #[test]
    fn build_after_memoise_is_seen_through_the_memo() {
        // PROTO 2; c__main__\nC\n; EMPTY_TUPLE; NEWOBJ; BINPUT 0; EMPTY_DICT; BUILD; POP;
        // BINGET 0; STOP — the object fetched back from the memo carries its state.
        let bytes = b"\x80\x02c__main__\nC\n)\x81q\x00}b0h\x00.";
        let p = Pickle::parse(bytes).unwrap();
        assert!(matches!(p.get(p.root()), Value::Object { state: Some(_), .. }));
    }

    #[test]
    fn unknown_opcodes_truncation_and_underflow_are_errors_with_offsets() {
        for (bytes, want) in [
            (&b"\x80\x02\xff"[..], "at byte 2: unsupported opcode 0xff"),
            (&b"\x80\x02X\x10\x00\x00\x00ab"[..], "length 16 runs past the end"),
            (&b"\x80\x02."[..], "stack underflow"),
            (&b"\x80\x02h\x07."[..], "memo key 7 was never stored"),
            (&b"\x80\x02(K\x01"[..], "truncated"),
        ] {
            let msg = Pickle::parse(bytes).unwrap_err().to_string();
            assert!(msg.contains(want), "{msg}");
        }
    }

    #[test]
    fn quoted_and_escaped_text() {
        assert_eq!(unquote(r"'a\'b\x00\n'").unwrap(), b"a'b\x00\n");
        assert_eq!(raw_unicode_unescape(r"caf\u00e9").unwrap(), "café");
        assert!(unquote("'open").is_none());
    }
}
