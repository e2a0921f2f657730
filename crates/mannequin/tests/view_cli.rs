//! `mannequin view` as a user runs it: the server refuses everything outside the viewed folder,
//! and in headless Chromium the page draws a dressed walk and a trained avatar's Gaussians where
//! the project's own renderers draw them, animated, with no console errors.

use std::io::{Read, Write};
use std::net::{TcpStream, UdpSocket};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

use burn::tensor::Device;
use mannequin_avatar::Avatar;
use mannequin_body::Motion;
use mannequin_data::image::Image;
use mannequin_splat::Camera;
use serde_json::json;

mod common;
use common::{mannequin, ok, one_line_error, s, scratch, tiny_avatar};

#[path = "../../../tools/browser.rs"]
mod browser;
use browser::{Browser, ViewServer};

/// The raw response of the viewer on `port` to `request`, sent as is.
fn raw(port: u16, request: &[u8]) -> String {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).unwrap();
    stream.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    // A server that stops reading early may reset the connection: what came back still counts.
    let _ = stream.write_all(request);
    let mut reply = Vec::new();
    let _ = stream.read_to_end(&mut reply);
    String::from_utf8_lossy(&reply).into_owned()
}

fn get(port: u16, target: &str) -> String {
    raw(port, format!("GET {target} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n").as_bytes())
}

fn status(reply: &str) -> u16 {
    reply
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {reply:?}"))
}

/// Only the viewed folder's files and the page are served, to loopback clients, read-only.
#[test]
fn the_server_refuses_everything_outside_the_folder() {
    let dir = scratch("view-security");
    let (inside, outside) = (dir.join("shown"), dir.join("secret"));
    std::fs::create_dir_all(&inside).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(outside.join("key.txt"), "secret").unwrap();
    std::os::unix::fs::symlink(outside.join("key.txt"), inside.join("link.txt")).unwrap();
    std::os::unix::fs::symlink(&outside, inside.join("escape")).unwrap();
    ok(mannequin(&["motion", "walk", "--seconds", "0.2", "-o", s(&dir.join("walk.npz"))]));
    ok(mannequin(&[
        "body",
        "animate",
        "--body",
        "default-lod1",
        "--motion",
        s(&dir.join("walk.npz")),
        "-o",
        s(&inside.join("walk.glb")),
    ]));
    let viewer = ViewServer::start(&[s(&inside)]);

    let page = get(viewer.port, "/");
    assert_eq!(status(&page), 200, "{page}");
    assert!(page.contains("viewer.js"));
    let glb = get(viewer.port, "/files/walk.glb");
    assert_eq!(status(&glb), 200);
    assert!(get(viewer.port, "/scene.json").contains("/files/walk.glb"));

    let refused = [
        ("/files/../secret/key.txt", 403),
        ("/files/%2e%2e/secret/key.txt", 403),
        ("/files/%2E%2E%2Fsecret%2Fkey.txt", 403),
        ("/files/..%5csecret%5ckey.txt", 403),
        ("/files//etc/passwd", 403),
        ("/files/%2fetc%2fpasswd", 403),
        ("/files/link.txt", 403),
        ("/files/escape/key.txt", 403),
        ("/files/%252e%252e/secret/key.txt", 404),
        ("/files/walk.glb%00.txt", 403),
        ("/files/%zz", 400),
        ("/../secret/key.txt", 404),
        ("/etc/passwd", 404),
    ];
    for (target, code) in refused {
        let reply = get(viewer.port, target);
        assert_eq!(status(&reply), code, "{target}: {reply}");
        assert!(!reply.contains("secret\n") || reply.contains("only"), "{target} leaked: {reply}");
    }
    let port = viewer.port;
    let writes = [
        format!("POST /files/walk.glb HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 2\r\n\r\nhi"),
        format!("PUT /files/new.txt HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 2\r\n\r\nhi"),
        format!("DELETE /files/walk.glb HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n"),
    ];
    for request in &writes {
        assert_eq!(status(&raw(viewer.port, request.as_bytes())), 405, "{request}");
    }
    assert!(!inside.join("new.txt").exists() && inside.join("walk.glb").exists());
    let with_body =
        format!("GET /files/walk.glb HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 5\r\n\r\nhello");
    assert_eq!(status(&raw(viewer.port, with_body.as_bytes())), 413);
    let huge = format!("GET /{} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n", "a".repeat(20_000));
    assert_eq!(status(&raw(viewer.port, huge.as_bytes())), 431);
    let rebound = "GET /files/walk.glb HTTP/1.1\r\nHost: attacker.example\r\n\r\n";
    assert_eq!(status(&raw(viewer.port, rebound.as_bytes())), 403);

    // Loopback only: the machine's own outward address (where it has one) is not served.
    let outward = UdpSocket::bind("0.0.0.0:0")
        .and_then(|u| u.connect("10.255.255.255:9").and_then(|()| u.local_addr()))
        .map(|a| a.ip())
        .ok()
        .filter(|ip| !ip.is_loopback() && !ip.is_unspecified());
    match outward {
        Some(ip) => assert!(
            TcpStream::connect_timeout(&(ip, viewer.port).into(), Duration::from_secs(2)).is_err(),
            "the viewer answered on {ip}"
        ),
        None => eprintln!("note: this machine has no outward address; loopback-only binding not probed"),
    }

    let o = mannequin(&["view", s(&outside), "--port", "0"]);
    one_line_error(&o, &["nothing to show", "avatar folder"]);
}

/// A camera file (OpenCV, as `splat render --camera` reads it) looking at the body from the
/// front, from 3.6 m.
fn front_camera(size: usize) -> (Camera, String) {
    let f = size as f64 * 1.3;
    let c = size as f64 / 2.0;
    let extrinsic =
        [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, -0.3], [0.0, 0.0, -1.0, 3.6], [0.0, 0.0, 0.0, 1.0]];
    let camera = Camera {
        width: size,
        height: size,
        intrinsic: [[f, 0.0, c], [0.0, f, c], [0.0, 0.0, 1.0]],
        extrinsic,
        near: 0.01,
        far: 100.0,
    };
    let text =
        json!({ "width": size, "height": size, "K": camera.intrinsic, "extrinsic": extrinsic }).to_string();
    (camera, text)
}

fn percent_encode(text: &str) -> String {
    text.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect()
}

/// The page's drawing at time `t`: a screenshot over a white and over a black background, and
/// the coverage of each pixel, 1 − |white − black| (1 where something opaque is drawn).
fn coverage_at(browser: &mut Browser, t: f64, size: usize) -> (Image, Vec<f32>) {
    let mut shots = Vec::new();
    for background in ["#ffffff", "#000000"] {
        browser
            .eval(&format!("window.mannequin.setBackground('{background}'); window.mannequin.setTime({t})"));
        // Spark sorts and regenerates splats over a few frames after the bones move.
        browser.eval(
            "new Promise(r => { const f0 = window.mannequin.frames; \
             const tick = () => window.mannequin.frames >= f0 + 20 ? setTimeout(() => r(true), 300) \
             : requestAnimationFrame(tick); tick(); })",
        );
        let png = browser.screenshot(size as u32, size as u32);
        shots.push(Image::decode_png(Path::new("screenshot.png"), &png).unwrap());
    }
    let coverage = shots[0]
        .pixels
        .iter()
        .zip(&shots[1].pixels)
        .map(|(w, b)| 1.0 - (0..3).map(|k| (w[k] - b[k]).abs()).sum::<f32>() / 3.0)
        .collect();
    (shots.swap_remove(0), coverage)
}

/// The page's silhouette against the project renderer's of the same frame: the person fills at
/// least 5 % of the view, and the two overlap with IoU ≥ 0.9.
fn same_silhouette(page: &[bool], truth: &[bool], what: &str) {
    let covered = truth.iter().filter(|&&t| t).count();
    assert!(covered * 20 > truth.len(), "{what}: the person covers {covered} pixels");
    let both = page.iter().zip(truth).filter(|(x, y)| **x && **y).count();
    let either = page.iter().zip(truth).filter(|(x, y)| **x || **y).count();
    let iou = both as f64 / either.max(1) as f64;
    eprintln!("{what}: silhouette IoU {iou:.3}");
    assert!(iou >= 0.9, "{what}: silhouette IoU {iou:.3} against the project's own render");
}

/// The two timeline positions drew different pictures (the animation plays), and the console
/// stayed free of errors.
fn played_cleanly(drawn: &[Vec<bool>], browser: &Browser) {
    let moved = drawn[0].iter().zip(&drawn[1]).filter(|(a, b)| a != b).count();
    assert!(moved * 200 > drawn[0].len(), "the two times differ in only {moved} pixels");
    assert!(browser.errors.is_empty(), "console errors: {:?}", browser.errors);
}

/// Opens `url` with the fixed camera, waits for the ready marker, and returns the browser.
fn open(url: &str, camera_json: &str, size: usize) -> Option<Browser> {
    let mut browser = Browser::launch(size as u32 + 280, size as u32 + 40)?;
    browser.navigate(&format!("{url}/?camera={}&t=0&ui=0", percent_encode(camera_json)));
    browser.wait_for("window.mannequin?.ready === true", Duration::from_secs(120));
    Some(browser)
}

/// The dressed walk (`dress` output: skinned body and garments as morph targets in one .glb)
/// drawn by the page matches `dress`'s own frames of the same camera, at two times that differ.
#[test]
fn a_dressed_walk_plays_in_the_browser() {
    let dir = scratch("view-dress");
    let size = 256;
    let (_, camera_json) = front_camera(size);
    std::fs::write(dir.join("camera.json"), &camera_json).unwrap();
    ok(mannequin(&["motion", "walk", "--seconds", "1", "-o", s(&dir.join("walk.npz"))]));
    let out = dir.join("dressed");
    let o = Command::new(env!("CARGO_BIN_EXE_mannequin"))
        .args([
            "dress",
            "--garments",
            "pants,tshirt",
            "--motion",
            s(&dir.join("walk.npz")),
            "--no-simulation",
        ])
        .args(["--camera", s(&dir.join("camera.json")), "--out", s(&out)])
        .env("XDG_CACHE_HOME", dir.join("cache"))
        .output()
        .unwrap();
    ok(o);
    let viewer = ViewServer::start(&[s(&out)]);
    let Some(mut browser) = open(&viewer.url, &camera_json, size) else { return };
    let layers = browser.eval("window.mannequin.layers");
    assert!(layers.as_array().is_some_and(|l| l.len() >= 3), "body and two garments: {layers}");

    let mut drawn = Vec::new();
    for frame in [3usize, 21] {
        let (shot, coverage) = coverage_at(&mut browser, frame as f64 / 30.0, size);
        let page: Vec<bool> = coverage.iter().map(|&c| c > 0.5).collect();
        let truth = Image::read_png(&out.join(format!("frames/frame_{frame:04}.png"))).unwrap();
        let truth: Vec<bool> = truth.pixels.iter().map(|p| p.iter().any(|&c| c < 0.999)).collect();
        shot.write_png(&dir.join(format!("page_{frame:04}.png"))).unwrap();
        same_silhouette(&page, &truth, &format!("dress frame {frame}"));
        drawn.push(page);
    }
    played_cleanly(&drawn, &browser);

    // A .glb dropped on the page joins the scene as more layers.
    let dropped = browser.eval(
        "(async () => { const bytes = await (await fetch('/files/dressed.glb')).arrayBuffer(); \
           const before = window.mannequin.layers.length; const data = new DataTransfer(); \
           data.items.add(new File([bytes], 'again.glb')); \
           document.dispatchEvent(new DragEvent('drop', { dataTransfer: data, cancelable: true })); \
           for (let i = 0; i < 200 && window.mannequin.layers.length === before; i++) \
             await new Promise(r => setTimeout(r, 50)); \
           return window.mannequin.layers.length - before; })()",
    );
    assert!(dropped.as_u64().is_some_and(|n| n >= 3), "a dropped .glb added {dropped} layers");
    assert!(browser.errors.is_empty(), "console errors: {:?}", browser.errors);
}

/// A trained avatar's Gaussians, skinned to its skeleton and played on the page, cover what the
/// project's splat renderer draws of the same frame (the binding itself), at two times.
#[test]
fn a_trained_avatar_walks_as_gaussians_in_the_browser() {
    let dir = scratch("view-avatar");
    let (data, model) = tiny_avatar(&dir);
    ok(mannequin(&[
        "eval",
        "--avatar",
        s(&model),
        "--data",
        s(&data),
        "--samples",
        "500",
        "--json",
        s(&dir.join("eval.json")),
    ]));
    let size = 256;
    let (camera, camera_json) = front_camera(size);
    // Two motions to offer: the first is the procedural walk the page plays by default.
    let (walk4, walk2) = (dir.join("walk4.npz"), dir.join("walk2.npz"));
    ok(mannequin(&["motion", "walk", "--seconds", "4", "--fps", "30", "-o", s(&walk4)]));
    ok(mannequin(&["motion", "walk", "--seconds", "2", "--fps", "30", "-o", s(&walk2)]));
    let motions = format!("{},{}", s(&walk4), s(&walk2));
    let viewer = ViewServer::start(&[s(&model), "--data", s(&data), "--motion", &motions]);
    let Some(mut browser) = open(&viewer.url, &camera_json, size) else { return };
    // The first novel view `eval` rendered, beside its ground truth from the dataset.
    let compare = browser.eval(
        "Promise.all([...document.querySelectorAll('#compare img')].map(i => i.decode().then(() => [i.alt, i.naturalWidth])))",
    );
    assert_eq!(compare, json!([["render", 96], ["ground truth", 96]]), "the side-by-side images");

    let avatar = Avatar::load(&model, &Device::flex()).unwrap();
    let walk = Motion::walk_cycle(4.0, 30.0);
    let mut drawn = Vec::new();
    for frame in [10usize, 40] {
        let (pose, transl) = walk.frame_pose(frame, avatar.canonical.num_joints()).unwrap();
        let posed = avatar.pose(&pose, transl).unwrap();
        let rendered = avatar.render(&posed, &camera).unwrap();
        let alpha: Vec<f32> = rendered.alpha().into_data().iter::<f32>().collect();
        let rgb: Vec<f32> = rendered.rgb().into_data().iter::<f32>().collect();
        let truth: Vec<bool> = alpha.iter().map(|&a| a > 0.5).collect();
        let (shot, coverage) = coverage_at(&mut browser, frame as f64 / 30.0, size);
        shot.write_png(&dir.join(format!("page_{frame:04}.png"))).unwrap();
        let page: Vec<bool> = coverage.iter().map(|&c| c > 0.5).collect();
        same_silhouette(&page, &truth, &format!("avatar frame {frame}"));
        // Colour over white (the render is channel-major): the page draws the same Gaussians.
        let n = size * size;
        let person: Vec<usize> = (0..n).filter(|&i| page[i] || truth[i]).collect();
        let squared: f64 = person
            .iter()
            .flat_map(|&i| (0..3).map(move |c| (i, c)))
            .map(|(i, c)| f64::from(shot.pixels[i][c] - rgb[c * n + i]).powi(2))
            .sum();
        let psnr = -10.0 * (squared / (3 * person.len()) as f64).log10();
        eprintln!("avatar frame {frame}: PSNR {psnr:.1} dB over the person");
        assert!(psnr >= 28.0, "frame {frame}: PSNR {psnr:.1} dB against the avatar's own render");
        drawn.push(page);
    }
    played_cleanly(&drawn, &browser);

    // The second motion replaces the first on the timeline, and the avatar still shows.
    assert_eq!(browser.eval("window.mannequin.motions()"), json!(["walk4", "walk2"]));
    browser.eval("window.mannequin.chooseMotion(1).then(() => true)");
    let short = Motion::read(&walk2).unwrap();
    let duration = browser.eval("window.mannequin.duration").as_f64().unwrap();
    let expected = (short.num_frames() - 1) as f64 / f64::from(short.fps);
    assert!((duration - expected).abs() < 1e-3, "duration {duration} s after choosing walk2 ({expected} s)");
    let (_, coverage) = coverage_at(&mut browser, 0.5, size);
    let shown = coverage.iter().filter(|&&c| c > 0.5).count();
    assert!(shown * 20 > size * size, "after choosing walk2 the avatar covers {shown} pixels");
    assert!(browser.errors.is_empty(), "console errors: {:?}", browser.errors);
}
