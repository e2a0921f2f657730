//! A read-only HTTP/1.1 server for the viewer, on loopback only: GET and HEAD of what the site
//! answers for a path (the embedded page, the scene's generated files and the files under the
//! viewed folder), nothing else. One request per connection; a request head is at most
//! [`MAX_HEAD`] bytes and carries no body.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Component, Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

/// The largest request head read; a browser's GET is well under 2 KiB.
pub const MAX_HEAD: usize = 8 * 1024;

/// A response: status, content type and body.
pub struct Response {
    pub status: u16,
    pub content_type: &'static str,
    pub body: Vec<u8>,
}

impl Response {
    pub fn text(status: u16, message: &str) -> Self {
        Self { status, content_type: "text/plain; charset=utf-8", body: format!("{message}\n").into_bytes() }
    }
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        413 => "Content Too Large",
        431 => "Request Header Fields Too Large",
        _ => "Internal Server Error",
    }
}

/// Serves `get`'s response to each GET of a path (the URL's path, still %-encoded) on `listener`
/// until the process ends, a thread per connection.
pub fn serve(listener: TcpListener, get: impl Fn(&str) -> Response + Send + Sync + 'static) {
    let port = listener.local_addr().map(|a| a.port()).unwrap_or(0);
    let get = Arc::new(get);
    for stream in listener.incoming().flatten() {
        let get = Arc::clone(&get);
        std::thread::spawn(move || {
            if let Err(e) = handle(stream, &*get, port) {
                tracing::debug!("connection: {e}");
            }
        });
    }
}

fn handle(mut stream: TcpStream, get: &dyn Fn(&str) -> Response, port: u16) -> std::io::Result<()> {
    stream.set_read_timeout(Some(Duration::from_secs(10)))?;
    stream.set_write_timeout(Some(Duration::from_secs(60)))?;
    let (response, head_only) = match read_head(&mut stream)? {
        Some(head) => {
            let head_only = head.starts_with("HEAD ");
            (respond(&head, get, port), head_only)
        }
        None => (Response::text(431, "the request head is over 8 KiB"), false),
    };
    let header = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\n\
         X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
        response.status,
        reason(response.status),
        response.content_type,
        response.body.len()
    );
    stream.write_all(header.as_bytes())?;
    if !head_only {
        stream.write_all(&response.body)?;
    }
    stream.flush()
}

/// The request head up to its blank line, or `None` when it is longer than [`MAX_HEAD`].
fn read_head(stream: &mut TcpStream) -> std::io::Result<Option<String>> {
    let mut head = Vec::with_capacity(1024);
    let mut chunk = [0u8; 1024];
    while !head.windows(4).any(|w| w == b"\r\n\r\n") {
        if head.len() > MAX_HEAD {
            return Ok(None);
        }
        let n = stream.read(&mut chunk)?;
        if n == 0 {
            break;
        }
        head.extend_from_slice(&chunk[..n]);
    }
    Ok(Some(String::from_utf8_lossy(&head).into_owned()))
}

/// The response to one request head.
fn respond(head: &str, get: &dyn Fn(&str) -> Response, port: u16) -> Response {
    let mut lines = head.split("\r\n");
    let request = lines.next().unwrap_or_default();
    let mut parts = request.split(' ');
    let (Some(method), Some(target), Some(version)) = (parts.next(), parts.next(), parts.next()) else {
        return Response::text(400, "expected 'METHOD /path HTTP/1.1'");
    };
    if !version.starts_with("HTTP/1.") {
        return Response::text(400, "expected HTTP/1.x");
    }
    if method != "GET" && method != "HEAD" {
        return Response::text(405, "the viewer only reads: GET and HEAD");
    }
    let mut host_ok = false;
    for line in lines.take_while(|l| !l.is_empty()) {
        let Some((name, value)) = line.split_once(':') else {
            return Response::text(400, "a header line without ':'");
        };
        let (name, value) = (name.trim().to_ascii_lowercase(), value.trim());
        if (name == "content-length" && value != "0") || name == "transfer-encoding" {
            return Response::text(413, "the viewer takes no request bodies");
        }
        // A page on another site must not read these files through a name that resolves here
        // (DNS rebinding): only loopback names are served.
        if name == "host" {
            host_ok =
                ["127.0.0.1", "localhost"].iter().any(|h| value == *h || value == format!("{h}:{port}"));
        }
    }
    if !host_ok {
        return Response::text(403, "only requests to 127.0.0.1 or localhost are served");
    }
    let path = target.split(['?', '#']).next().unwrap_or_default();
    get(path)
}

/// The file under `root` that a URL path (after `/files/`) names, or why it is refused: the path
/// is percent-decoded once, must be relative with no `.` or `..` part, and must resolve, links
/// followed, to a regular file inside `root` (itself canonical).
pub fn resolve(root: &Path, encoded: &str) -> Result<PathBuf, Response> {
    let forbidden = |why: &str| Response::text(403, why);
    let decoded = percent_decode(encoded).ok_or_else(|| Response::text(400, "a malformed %-escape"))?;
    if decoded.contains(['\0', '\\']) {
        return Err(forbidden("NUL and backslash are not allowed in paths"));
    }
    let relative = Path::new(&decoded);
    let plain = decoded.split('/').all(|p| !p.is_empty() && p != "." && p != "..")
        && relative.components().all(|c| matches!(c, Component::Normal(_)));
    if !plain {
        return Err(forbidden("only plain relative paths inside the viewed folder are served"));
    }
    let full = root.join(relative).canonicalize().map_err(|_| Response::text(404, "no such file"))?;
    if !full.starts_with(root) {
        return Err(forbidden("the path leads out of the viewed folder"));
    }
    if !full.is_file() {
        return Err(Response::text(404, "not a file"));
    }
    Ok(full)
}

/// `%XX` escapes decoded to bytes, which must then be UTF-8; `None` for a bad escape.
fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let digit = |k: usize| bytes.get(i + k).and_then(|&c| char::from(c).to_digit(16));
            out.push((digit(1)? * 16 + digit(2)?) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The content type of a served file, by extension.
pub fn content_type(path: &Path) -> &'static str {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("glb") => "model/gltf-binary",
        Some("gltf" | "json") => "application/json",
        Some("png") => "image/png",
        Some("jpg" | "jpeg") => "image/jpeg",
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript; charset=utf-8",
        _ => "application/octet-stream",
    }
}
