//! `mannequin <verb>`: the one binary. Each verb lives in its own module with its clap
//! arguments and a `run` function; this file only dispatches and reports errors.

mod eval;
mod progress;
mod synth;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "mannequin", version, about = "Animatable, clothed 3D digital humans")]
struct Cli {
    /// Log more (-v: debug, -vv: trace). RUST_LOG overrides this.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Compare predictions with a ground-truth dataset: PSNR, SSIM, LPIPS, normal and geometry errors.
    Eval(eval::Args),
    /// Generate a synthetic clothed subject with full ground truth, in the dataset layout.
    Synth(synth::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    progress::init_logging(cli.verbose);
    let result: anyhow::Result<()> = match cli.command {
        Command::Eval(args) => eval::run(args),
        Command::Synth(args) => synth::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // One readable line: the chain of causes, outermost first.
            eprintln!("error: {}", e.chain().map(|c| c.to_string()).collect::<Vec<_>>().join(": "));
            std::process::ExitCode::FAILURE
        }
    }
}
