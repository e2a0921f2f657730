//! Issue 23's viewer benchmark: the frame rate `mannequin view` reaches in headless Chromium
//! (software WebGL on this machine's CPU: Mesa's llvmpipe, see tools/browser.rs; `CHROMIUM_FLAGS`
//! picks another), read from the page's own frame counter
//! while the avatar walks. The baseline, measured in the same run and browser, is the same page
//! drawing only the avatar's skinned mesh (its Gaussians toggled off).
//!
//! The avatar is the default body's Tavatar binding (face and vertex Gaussians, about 40k),
//! untrained: the splat count and the page's work do not depend on the colours. `--avatar DIR`
//! measures a trained one instead.
//!
//! `cargo bench -p mannequin --bench view -- [--avatar DIR] [--seconds 10] [--width 960] [--height 540]`

use std::path::PathBuf;
use std::time::Duration;

use burn::tensor::Device;
use mannequin_avatar::{Avatar, AvatarConfig, Canonical, Method};
use mannequin_body::BodyModel;

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
use bench_args::arg;

#[path = "../../../tools/browser.rs"]
mod browser;
use browser::{Browser, ViewServer};

/// The page's frames per second over `seconds` of playing, after a second to settle.
fn frame_rate(browser: &mut Browser, seconds: f64) -> f64 {
    std::thread::sleep(Duration::from_secs(1));
    let script = format!(
        "new Promise(r => {{ const f0 = window.mannequin.frames, t0 = performance.now(); \
         setTimeout(() => r(1000 * (window.mannequin.frames - f0) / (performance.now() - t0)), {}); }})",
        (seconds * 1000.0) as u64
    );
    browser.eval(&script).as_f64().expect("a frame rate")
}

fn main() {
    let seconds: f64 = arg("--seconds", 10.0);
    let (width, height): (u32, u32) = (arg("--width", 960), arg("--height", 540));
    let avatar_dir = match arg("--avatar", String::new()) {
        dir if !dir.is_empty() => PathBuf::from(dir),
        _ => {
            let dir = std::env::temp_dir().join("mannequin-view-bench-avatar");
            let canonical = Canonical::from_body(&BodyModel::default_body(), &[], 0).expect("default body");
            let avatar = Avatar::new(AvatarConfig::new(Method::Tavatar, 0), canonical, &Device::flex())
                .expect("an avatar");
            avatar.save(&dir).expect("saving the avatar");
            dir
        }
    };
    let splats = Avatar::load(&avatar_dir, &Device::flex()).expect("loading the avatar").num_gaussians();

    let server = ViewServer::start(&[avatar_dir.to_str().unwrap()]);
    let Some(mut browser) = Browser::launch(width, height) else { return };
    browser.navigate(&server.url);
    browser.wait_for("window.mannequin?.ready === true", Duration::from_secs(180));
    let splat_rate = frame_rate(&mut browser, seconds);
    let update_ms = browser.eval("window.mannequin.splatUpdateMs").as_f64().unwrap_or(f64::NAN);
    // Paused, the splats are drawn but not re-posed: the drawing's own rate.
    browser.eval("document.getElementById('play').click(); true");
    let drawing_rate = frame_rate(&mut browser, seconds);
    browser.eval("document.getElementById('play').click(); true");
    // Toggle the Gaussians off and the mesh on, as a user would in the layers panel.
    browser.eval(
        "for (const box of document.querySelectorAll('#layers input')) { \
           const name = box.parentElement.textContent.trim(); \
           if ((name === 'avatar' && box.checked) || (name === 'body' && !box.checked)) box.click(); } true",
    );
    let mesh_rate = frame_rate(&mut browser, seconds);
    assert!(browser.errors.is_empty(), "console errors: {:?}", browser.errors);

    let webgl = browser.eval(
        "(() => { const gl = document.createElement('canvas').getContext('webgl2'); \
           return gl.getParameter(gl.getExtension('WEBGL_debug_renderer_info').UNMASKED_RENDERER_WEBGL); })()",
    );
    println!("mannequin view, headless Chromium, {width}×{height}, WebGL on {webgl}:");
    println!("| page | frames/s |");
    println!("| --- | --- |");
    println!(
        "| {splats} Gaussians, walking (posed and sorted each frame: {update_ms:.0} ms last frame) | {splat_rate:.1} |"
    );
    println!("| the same, paused (drawing only) | {drawing_rate:.1} |");
    println!("| the skinned mesh alone, walking (baseline) | {mesh_rate:.1} |");
    println!("ratio Gaussians / mesh: {:.2}", splat_rate / mesh_rate);
    println!(
        "target: ≥ 15 frames/s for a 40k-splat avatar; measured {splat_rate:.1} ({:.2}× the target)",
        splat_rate / 15.0
    );
}
