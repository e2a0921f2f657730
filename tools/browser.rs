//! Headless Chromium driven over the DevTools protocol, for the viewer's tests and benchmark
//! (included with `#[path]`). Chromium's `--remote-debugging-pipe` reads commands on fd 3 and
//! writes replies and events on fd 4, each a JSON message ended by a NUL byte; a shell `exec`
//! puts the child's stdin and stdout on those descriptors, so no socket or crate is needed.
//!
//! Where Chromium is missing the browser tests fail under CI (`CI` or `MANNEQUIN_REQUIRE_BROWSER`
//! set), so CI cannot pass without them; elsewhere they warn on the terminal and skip.
#![allow(dead_code)] // The tests and the benchmark use different parts.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// Where Debian's package puts it; `CHROMIUM` overrides.
const CHROMIUM: &str = "/usr/bin/chromium";

/// WebGL on the CPU through Mesa's llvmpipe (EGL, no display needed): ten times the frame rate
/// of Chromium's own SwiftShader on the viewer's splats (docs/viewer.md). `CHROMIUM_FLAGS`
/// replaces these: `--use-angle=swiftshader --enable-unsafe-swiftshader` for SwiftShader, or
/// `--use-angle=vulkan` for a real GPU.
const SOFTWARE_WEBGL: &str = "--use-angle=gl-egl --ignore-gpu-blocklist";

pub struct Browser {
    child: Child,
    to: ChildStdin,
    from: BufReader<ChildStdout>,
    next_id: u64,
    session: String,
    profile: PathBuf,
    /// Console errors, uncaught exceptions and error log entries (failed loads, WebGL), as text.
    pub errors: Vec<String>,
    /// Every console message, for a failing test's report.
    pub console: Vec<String>,
}

fn required() -> bool {
    let set = |var| std::env::var(var).is_ok_and(|v| !matches!(v.as_str(), "" | "0" | "false"));
    set("CI") || set("MANNEQUIN_REQUIRE_BROWSER")
}

impl Browser {
    /// A headless Chromium with one page of `width`×`height` CSS pixels (device scale 1) and
    /// software WebGL (SwiftShader), or `None` when Chromium is not installed and not required.
    pub fn launch(width: u32, height: u32) -> Option<Self> {
        let exe = std::env::var("CHROMIUM").unwrap_or_else(|_| CHROMIUM.into());
        if !Path::new(&exe).exists() {
            let message = format!(
                "{exe} not found, so the browser tests did not run; install: apt-get install chromium"
            );
            assert!(!required(), "{message} (required under CI or MANNEQUIN_REQUIRE_BROWSER)");
            let _ = writeln!(std::io::stderr(), "warning: {message}");
            return None;
        }
        let profile =
            std::env::temp_dir().join(format!("mannequin-chromium-{}-{}", std::process::id(), width));
        let _ = std::fs::remove_dir_all(&profile);
        let log =
            std::fs::File::create(std::env::temp_dir().join(format!("{}.log", profile.display()))).unwrap();
        // Without the background-networking flags Chromium keeps dialling Google's hosts, which a
        // closed network refuses many at a time.
        let mut child = Command::new("bash")
            .arg("-c")
            .arg(r#"exec "$0" "$@" 3<&0 4>&1 0</dev/null 1>/dev/null"#)
            .arg(&exe)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--disable-background-timer-throttling",
                "--disable-renderer-backgrounding",
                "--remote-debugging-pipe",
                &format!("--user-data-dir={}", profile.display()),
                &format!("--window-size={width},{height}"),
                "about:blank",
            ])
            .args(
                std::env::var("CHROMIUM_FLAGS").unwrap_or_else(|_| SOFTWARE_WEBGL.into()).split_whitespace(),
            )
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(log)
            .spawn()
            .expect("starting chromium");
        let to = child.stdin.take().unwrap();
        let from = BufReader::new(child.stdout.take().unwrap());
        let mut browser = Browser {
            child,
            to,
            from,
            next_id: 0,
            session: String::new(),
            profile,
            errors: vec![],
            console: vec![],
        };
        let targets = browser.command("Target.getTargets", json!({}));
        let page = targets["targetInfos"]
            .as_array()
            .and_then(|t| t.iter().find(|t| t["type"] == "page"))
            .expect("chromium opened a page")["targetId"]
            .clone();
        let attached = browser.command("Target.attachToTarget", json!({ "targetId": page, "flatten": true }));
        browser.session = attached["sessionId"].as_str().expect("a session").to_string();
        for domain in ["Runtime.enable", "Log.enable", "Page.enable"] {
            browser.command(domain, json!({}));
        }
        browser.command(
            "Emulation.setDeviceMetricsOverride",
            json!({ "width": width, "height": height, "deviceScaleFactor": 1, "mobile": false }),
        );
        Some(browser)
    }

    /// Sends a command (to the page's session once attached) and returns its result, keeping the
    /// events that arrive meanwhile.
    pub fn command(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        let mut message = json!({ "id": id, "method": method, "params": params });
        if !self.session.is_empty() {
            message["sessionId"] = json!(self.session);
        }
        let mut bytes = serde_json::to_vec(&message).unwrap();
        bytes.push(0);
        self.to.write_all(&bytes).and_then(|()| self.to.flush()).expect("writing to chromium");
        loop {
            let mut raw = Vec::new();
            let n = self.from.read_until(0, &mut raw).expect("reading from chromium");
            assert!(n > 0, "chromium closed the pipe during {method}");
            raw.pop();
            let reply: Value = serde_json::from_slice(&raw).expect("chromium sends JSON");
            if reply["id"] == json!(id) {
                assert!(reply.get("error").is_none(), "{method}: {}", reply["error"]);
                return reply["result"].clone();
            }
            self.event(&reply);
        }
    }

    fn event(&mut self, event: &Value) {
        let p = &event["params"];
        match event["method"].as_str() {
            Some("Runtime.consoleAPICalled") => {
                let text: Vec<String> = p["args"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .map(|a| a.get("value").map_or_else(|| a["description"].to_string(), |v| v.to_string()))
                    .collect();
                let line = format!("console.{}: {}", p["type"].as_str().unwrap_or("?"), text.join(" "));
                if matches!(p["type"].as_str(), Some("error" | "assert")) {
                    self.errors.push(line.clone());
                }
                self.console.push(line);
            }
            Some("Runtime.exceptionThrown") => {
                let d = &p["exceptionDetails"];
                self.errors.push(format!("uncaught: {} {}", d["text"], d["exception"]["description"]));
            }
            Some("Log.entryAdded") if p["entry"]["level"] == "error" => {
                self.errors.push(format!("log: {} {}", p["entry"]["text"], p["entry"]["url"]));
            }
            _ => {}
        }
    }

    pub fn navigate(&mut self, url: &str) {
        self.command("Page.navigate", json!({ "url": url }));
    }

    /// The value of a JavaScript expression, promises awaited.
    pub fn eval(&mut self, expression: &str) -> Value {
        let r = self.command(
            "Runtime.evaluate",
            json!({ "expression": expression, "awaitPromise": true, "returnByValue": true }),
        );
        assert!(r.get("exceptionDetails").is_none(), "{expression}: {}", r["exceptionDetails"]);
        r["result"]["value"].clone()
    }

    /// Waits until `expression` is true, failing with the console's errors after `timeout`.
    pub fn wait_for(&mut self, expression: &str, timeout: Duration) {
        let start = Instant::now();
        while self.eval(expression) != json!(true) {
            assert!(
                start.elapsed() < timeout,
                "{expression} still false after {timeout:?}; errors: {:?}; console: {:?}",
                self.errors,
                self.console
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// A PNG screenshot of the page's top-left `width`×`height` CSS pixels.
    pub fn screenshot(&mut self, width: u32, height: u32) -> Vec<u8> {
        let clip = json!({ "x": 0, "y": 0, "width": width, "height": height, "scale": 1 });
        let r = self.command("Page.captureScreenshot", json!({ "format": "png", "clip": clip }));
        base64_decode(r["data"].as_str().expect("screenshot data"))
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

/// Standard base64 (with padding) to bytes.
fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let clean: Vec<u8> = text.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::with_capacity(clean.len() * 3 / 4);
    for chunk in clean.chunks(4) {
        let v: Vec<u32> = chunk.iter().map(|&c| u32::from(value(c))).collect();
        let n = v.iter().enumerate().fold(0u32, |acc, (i, &x)| acc | (x << (18 - 6 * i)));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

/// A running `mannequin view … --port 0` (the binary of the test or bench including this file),
/// stopped when dropped.
pub struct ViewServer {
    child: Child,
    /// `http://127.0.0.1:PORT`, without the trailing slash.
    pub url: String,
    pub port: u16,
}

impl ViewServer {
    pub fn start(args: &[&str]) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_mannequin"))
            .arg("view")
            .args(args)
            .args(["--port", "0"])
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("starting mannequin view");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
        let url = line
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in {line}"))
            .trim_end_matches('/')
            .to_string();
        let port = url.rsplit(':').next().unwrap().parse().unwrap();
        ViewServer { child, url, port }
    }
}

impl Drop for ViewServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
