//! The command line: parse, call the library, map errors to exit codes
//! (0 success, 2 usage error, 1 anything else; one line on stderr).

mod cli;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use cli::bench::BenchArgs;
use cli::compare::CompareArgs;
use cli::render::RenderArgs;
use cli::stitch::StitchArgs;
use whitted::scene;
use whitted::settings::{Encoding, Overrides, Preset};

#[derive(Parser)]
#[command(
    name = "whitted",
    version,
    about = "A Whitted-style ray tracer for scenes of spheres"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Open the viewer window on a scene (default: the built-in hw3 scene).
    View {
        /// A scene file (TOML).
        scene: Option<PathBuf>,
        /// Quality preset: draft, default, high or reference (docs/quality.md).
        #[arg(long, value_name = "PRESET")]
        quality: Option<Preset>,
        /// Bytes on screen: linear or srgb (overrides the scene's).
        #[arg(long, value_name = "ENCODING")]
        encoding: Option<Encoding>,
    },
    /// Render without a window and write image files.
    Render(RenderArgs),
    /// Put parts written with --tile or --region back together into the whole image.
    Stitch(StitchArgs),
    /// Time renders of a scene (median of several runs) and print a line in the form
    /// of the peer programs' results (`../shared/peers/run.sh`).
    Time {
        /// A scene file (TOML); default: the built-in hw3 scene.
        scene: Option<PathBuf>,
        /// Timed runs (after one warm-up).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Worker threads (default: all cores).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
        threads: Option<u32>,
        /// Time the viewer instead: this many views orbiting the scene, each rendered
        /// as the window renders it (no window; the blit is not included).
        #[arg(long, value_name = "VIEWS", value_parser = clap::value_parser!(u32).range(1..=100000))]
        orbit: Option<u32>,
        /// With --orbit: render each view in one full pass, without the preview the
        /// window puts first when a frame takes longer than 1/30 s (the render time of
        /// whole frames).
        #[arg(long, requires = "orbit")]
        no_preview: bool,
        /// With --orbit: also write each timed view as a scene file of the peer
        /// programs' format into this folder (view_01.txt, …), to time them on the same
        /// views.
        #[arg(long, value_name = "DIR", requires = "orbit")]
        views_to: Option<PathBuf>,
    },
    /// Measure run time against error over a grid of quality settings on several
    /// scenes; writes bench.csv, bench.md and bench.svg (docs/quality.md).
    Bench(BenchArgs),
    /// Compare two images of the same size: one line of RMSE, PSNR, largest
    /// difference, share of pixels off by more than one level and mean FLIP; exit
    /// status 1 past a threshold.
    Compare(CompareArgs),
    /// Print a built-in scene as a scene file.
    Scene {
        /// The built-in scene: only "hw3".
        #[arg(value_parser = ["hw3"])]
        name: String,
        /// Seed of the 48 small balls (2020 is the built-in scene).
        #[arg(long, default_value_t = scene::HW3_DEFAULT_SEED)]
        seed: u64,
    },
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help, --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            let subcommand = std::env::args().nth(1);
            eprintln!(
                "whitted: error: {}",
                usage_error_line(&e, subcommand.as_deref())
            );
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        None => cli::view(None, Overrides::default()),
        Some(Command::View {
            scene,
            quality,
            encoding,
        }) => cli::view(
            scene.as_deref(),
            Overrides {
                quality,
                encoding,
                ..Overrides::default()
            },
        ),
        Some(Command::Bench(args)) => cli::bench::bench_command(args),
        Some(Command::Render(args)) => cli::render::render_command(args),
        Some(Command::Stitch(args)) => cli::stitch::stitch_command(args),
        Some(Command::Compare(args)) => cli::compare::compare_command(args),
        Some(Command::Time {
            scene,
            runs,
            threads,
            orbit,
            no_preview,
            views_to,
        }) => cli::time_command(
            scene.as_deref(),
            runs,
            threads,
            orbit.map(|views| cli::Orbit {
                views,
                preview: !no_preview,
                views_to,
            }),
        ),
        Some(Command::Scene { name: _, seed }) => cli::scene_command(seed),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("whitted: error: {}", one_line(&e));
            // Bad option values are usage errors, like those clap finds.
            ExitCode::from(if cli::is_usage_error(&e) { 2 } else { 1 })
        }
    }
}

/// clap's message on one line, like every other error: the error itself and its hints
/// (a similar option, the possible values), without the usage block and without
/// clap's "error: " (the caller puts whitted's). `subcommand` is the first argument.
fn usage_error_line(e: &clap::Error, subcommand: Option<&str>) -> String {
    if let Some(line) = viewer_option_line(e, subcommand) {
        return format!("{line} (see --help)");
    }
    let text = e.to_string();
    let parts: Vec<&str> = text
        .lines()
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .map(str::trim)
        // "to pass '--width' as a value, use '-- --width'" only ever fits a scene file
        // named like an option; for a mistyped or misplaced option it misleads.
        .filter(|l| !l.is_empty() && !l.starts_with("tip: to pass"))
        .collect();
    let line = parts.join("; ");
    let line = line.strip_prefix("error: ").unwrap_or(&line);
    format!("{line} (see --help)")
}

/// For an option of `whitted render` given to the viewer (`whitted view --width 640`,
/// or `whitted --spp 4`): what to do instead.
fn viewer_option_line(e: &clap::Error, subcommand: Option<&str>) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let viewer = match subcommand {
        Some("view") => "whitted view",
        Some(arg) if arg.starts_with('-') => "whitted",
        _ => return None,
    };
    if e.kind() != ErrorKind::UnknownArgument {
        return None;
    }
    let Some(ContextValue::String(arg)) = e.get(ContextKind::InvalidArg) else {
        return None;
    };
    let option = arg.split('=').next().unwrap_or(arg);
    let instead = match option {
        "--width" | "--height" => format!(
            "the window is resizable, or set {} in the scene's [image] table",
            &option[2..]
        ),
        "--spp" | "--seed" => format!(
            "set {} in the scene's [image] table, or use --quality",
            &option[2..]
        ),
        "--depth" => "set max_depth in the scene's [image] table, or use --quality".into(),
        "-o" | "--output" | "--region" | "--tile" | "--threads" | "--reference" | "--quiet"
        | "-q" | "--ppm-binary" | "--frames" | "--frame" | "--orbit" => {
            "it is an option of `whitted render`".to_string()
        }
        _ => return None,
    };
    Some(format!("`{viewer}` takes no {option}: {instead}"))
}

/// The error and its causes on one line.
fn one_line(e: &anyhow::Error) -> String {
    e.chain()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(": ")
        .replace('\n', " ")
}
