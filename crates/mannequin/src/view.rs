//! `mannequin view`: a browser viewer for avatars, garments and cloth, served by the binary on
//! loopback (the page and its JavaScript are embedded; nothing is fetched from the internet).

mod http;
mod site;

use std::net::TcpListener;
use std::path::PathBuf;

use anyhow::{Context, Result};

use site::Site;

#[derive(clap::Args)]
pub struct Args {
    /// An avatar folder, a `dress` or `cloth simulate` output folder, a `.glb`, or a 3DGS `.ply`.
    path: PathBuf,
    /// The port on 127.0.0.1 (0: any free port).
    #[arg(long, default_value_t = 8765)]
    port: u16,
    /// Open the page in the system's browser.
    #[arg(long)]
    open: bool,
    /// Motions an avatar can play (AMASS or PeopleSnapshot `.npz`; repeat or separate with
    /// commas), offered before those in its folder; with none at all, a procedural walk.
    #[arg(long, value_delimiter = ',')]
    motion: Vec<PathBuf>,
    /// The avatar's dataset, to show a test view beside its ground truth (after `mannequin eval`).
    #[arg(long)]
    data: Option<PathBuf>,
}

pub fn run(args: Args) -> Result<()> {
    let site = Site::load(&args.path, &args.motion, args.data.as_deref())?;
    let listener = TcpListener::bind(("127.0.0.1", args.port)).with_context(|| {
        format!("listening on 127.0.0.1:{} (pass another --port, or 0 for any)", args.port)
    })?;
    let url = format!("http://127.0.0.1:{}/", listener.local_addr()?.port());
    println!("Mannequin viewer for {} at {url} (Ctrl-C to stop)", args.path.display());
    if args.open {
        open_browser(&url);
    }
    http::serve(listener, move |path| site.get(path));
    Ok(())
}

/// Launches the system browser on `url`, saying so when there is none.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") { "open" } else { "xdg-open" };
    match std::process::Command::new(opener).arg(url).spawn() {
        Ok(_) => tracing::info!("opened {url} with {opener}"),
        Err(e) => tracing::warn!("--open: could not run {opener} ({e}); open {url} yourself"),
    }
}
