//! The manifest's CSV (RFC 4180): comma-separated fields, double quotes around a field that holds
//! a comma, a quote (doubled) or a line break. Each record keeps the line it starts on, so an
//! error can name it.

use anyhow::{Result, bail};

/// One record: its fields and the 1-based line it starts on.
pub struct Record {
    pub line: usize,
    pub fields: Vec<String>,
}

/// Splits `text` into records; blank lines are skipped. `file` names the text in errors.
pub fn records(text: &str, file: &str) -> Result<Vec<Record>> {
    let mut out = Vec::new();
    let (mut fields, mut field) = (Vec::new(), String::new());
    let (mut line, mut start) = (1, 1);
    let (mut quoted, mut was_quoted) = (false, false);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => {
                line += usize::from(c == '\n');
                field.push(c);
            }
            (false, '"') if field.is_empty() && !was_quoted => (quoted, was_quoted) = (true, true),
            (false, '"') => {
                bail!("{file} line {line}: a quote inside an unquoted field; quote the whole field")
            }
            (false, ',') => {
                fields.push(std::mem::take(&mut field));
                was_quoted = false;
            }
            (false, '\r') if chars.peek() == Some(&'\n') => {}
            (false, '\n') => {
                fields.push(std::mem::take(&mut field));
                if !(fields.len() == 1 && fields[0].is_empty() && !was_quoted) {
                    out.push(Record { line: start, fields: std::mem::take(&mut fields) });
                }
                fields.clear();
                was_quoted = false;
                line += 1;
                start = line;
            }
            (false, c) => field.push(c),
        }
    }
    if quoted {
        bail!("{file} line {start}: a quoted field is not closed");
    }
    if !field.is_empty() || !fields.is_empty() || was_quoted {
        fields.push(field);
        out.push(Record { line: start, fields });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(text: &str) -> Vec<(usize, Vec<String>)> {
        records(text, "m.csv").unwrap().into_iter().map(|r| (r.line, r.fields)).collect()
    }

    #[test]
    fn quotes_commas_line_breaks_and_blank_lines() {
        let text = "id,input\r\na,\"x,y\"\n\nb,\"say \"\"hi\"\"\nthere\"\nc,\n";
        let got = rows(text);
        let want = [
            (1, vec!["id", "input"]),
            (2, vec!["a", "x,y"]),
            (4, vec!["b", "say \"hi\"\nthere"]),
            (6, vec!["c", ""]),
        ];
        assert_eq!(got.len(), want.len());
        for ((line, fields), (wline, wfields)) in got.iter().zip(want) {
            assert_eq!(*line, wline);
            assert_eq!(fields, &wfields);
        }
    }

    #[test]
    fn last_record_without_a_line_break() {
        assert_eq!(rows("a,b\nc,d")[1].1, ["c", "d"]);
    }

    #[test]
    fn broken_quoting_names_the_line() {
        let e = records("id\n\"open\n", "m.csv").err().unwrap().to_string();
        assert!(e.contains("m.csv line 2") && e.contains("not closed"), "{e}");
        let e = records("id\na\"b\n", "m.csv").err().unwrap().to_string();
        assert!(e.contains("m.csv line 2") && e.contains("quote"), "{e}");
    }
}
