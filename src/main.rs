//! The command line: parse, call the library, map errors to exit codes
//! (0 success, 2 usage error, 1 anything else; one line on stderr).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context};
use clap::{Args, Parser, Subcommand};

use whitted::bench::{self, BenchOptions};
use whitted::image_io::{self, Format};
use whitted::render::{self, RenderControl};
use whitted::scene::{self, Scene};
use whitted::settings::{Overrides, Precision, Preset, Region};

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
    },
    /// Render without a window and write image files.
    Render(RenderArgs),
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
    },
    /// Measure run time against error over a grid of quality settings on several
    /// scenes; writes bench.csv, bench.md and bench.svg (docs/quality.md).
    Bench(BenchArgs),
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

#[derive(Args)]
struct RenderArgs {
    /// A scene file (TOML); default: the built-in hw3 scene.
    scene: Option<PathBuf>,
    /// Output file, format by extension: .ppm .png .bmp .jpg .exr (repeatable).
    /// Default: output.ppm and output.png.
    #[arg(short, long = "output", value_name = "FILE", value_parser = parse_output)]
    output: Vec<PathBuf>,
    /// Write binary PPM (P6) instead of plain (P3).
    #[arg(long)]
    ppm_binary: bool,
    /// Image width in pixels (overrides the scene's).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    width: Option<u32>,
    /// Image height in pixels (overrides the scene's).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    height: Option<u32>,
    /// Samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    spp: Option<u32>,
    /// Maximum ray depth.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=64))]
    depth: Option<u32>,
    /// Sampling seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// Render only this rectangle: X,Y,W,H in output pixels, origin top-left.
    #[arg(long, value_name = "X,Y,W,H", value_parser = parse_region)]
    region: Option<Region>,
    /// Use the slow f64 reference renderer.
    #[arg(long)]
    reference: bool,
    /// Quality preset: draft, default, high or reference (docs/quality.md); the
    /// other options override its settings.
    #[arg(long, value_name = "PRESET")]
    quality: Option<Preset>,
    /// No progress bar and no closing line.
    #[arg(short, long)]
    quiet: bool,
}

impl RenderArgs {
    /// The options that override the scene's settings.
    fn overrides(&self) -> Overrides {
        Overrides {
            quality: self.quality,
            width: self.width,
            height: self.height,
            spp: self.spp,
            max_depth: self.depth,
            seed: self.seed,
            precision: self.reference.then_some(Precision::Reference),
            region: self.region,
            threads: self.threads.map(|t| t as usize),
        }
    }
}

#[derive(Args)]
struct BenchArgs {
    /// Folder for the outputs (and a cache of the slow reference images).
    #[arg(long, value_name = "DIR", default_value = "bench-out")]
    out: PathBuf,
    /// Image size of every render.
    #[arg(long, value_name = "WxH", default_value = "320x180", value_parser = bench::parse_size)]
    size: (u32, u32),
    /// Timed runs per setting, at least (the median is reported; settings that take
    /// milliseconds get up to 10 times as many).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    runs: u32,
    /// A tiny grid on small scenes, for a quick check.
    #[arg(long)]
    tiny: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// No progress bar and no summary.
    #[arg(short, long)]
    quiet: bool,
}

fn bench_command(args: BenchArgs) -> anyhow::Result<()> {
    let opts = BenchOptions {
        out: args.out,
        width: args.size.0,
        height: args.size.1,
        runs: args.runs as usize,
        tiny: args.tiny,
        threads: args.threads.map(|t| t as usize),
        progress: !args.quiet && std::io::stderr().is_terminal(),
    };
    let rows = bench::run(&opts)?;
    if !args.quiet {
        eprint!("{}", bench::summary(&rows, &opts.out));
    }
    Ok(())
}

fn parse_region(text: &str) -> Result<Region, String> {
    let parts: Vec<&str> = text.split(',').collect();
    let numbers: Result<Vec<u32>, _> = parts.iter().map(|p| p.trim().parse::<u32>()).collect();
    match numbers.as_deref() {
        Ok(&[x, y, width, height]) if width > 0 && height > 0 => Ok(Region {
            x,
            y,
            width,
            height,
        }),
        _ => Err("expected X,Y,W,H: four whole numbers, W and H at least 1".into()),
    }
}

/// An output path whose extension names a format we write (else a usage error).
fn parse_output(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    Format::from_path(&path, false).map_err(|e| e.to_string())?;
    Ok(path)
}

/// The built-in scene, embedded from the file the generator wrote
/// (`whitted scene hw3 > assets/scenes/hw3.toml`); a test keeps the two in step.
const BUILTIN_SCENE: &str = include_str!("../assets/scenes/hw3.toml");

fn builtin_scene() -> anyhow::Result<Scene> {
    let mut scene = Scene::from_toml_str(BUILTIN_SCENE, "assets/scenes/hw3.toml")
        .context("the built-in scene is broken")?;
    scene.name = "hw3".into();
    Ok(scene)
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
            eprintln!("{}", usage_error_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        None => view(None, None),
        Some(Command::View { scene, quality }) => view(scene.as_deref(), quality),
        Some(Command::Bench(args)) => bench_command(args),
        Some(Command::Render(args)) => render_command(args),
        Some(Command::Time {
            scene,
            runs,
            threads,
            orbit,
            no_preview,
        }) => time_command(scene.as_deref(), runs, threads, orbit, !no_preview),
        Some(Command::Scene { name: _, seed }) => scene_command(seed),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("whitted: error: {}", one_line(&e));
            ExitCode::from(1)
        }
    }
}

/// clap's message on one line, like every other error: the error itself and its hints
/// (a similar option, the possible values), without the usage block.
fn usage_error_line(e: &clap::Error) -> String {
    let text = e.to_string();
    let parts: Vec<&str> = text
        .lines()
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    format!("{} (see --help)", parts.join("; "))
}

/// The error and its causes on one line.
fn one_line(e: &anyhow::Error) -> String {
    e.chain()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(": ")
        .replace('\n', " ")
}

fn load_scene(path: Option<&Path>) -> anyhow::Result<Scene> {
    match path {
        None => builtin_scene(),
        Some(p) => Ok(Scene::load(p)?),
    }
}

fn view(path: Option<&Path>, quality: Option<Preset>) -> anyhow::Result<()> {
    let mut scene = load_scene(path)?;
    if let Some(preset) = quality {
        // As if the scene file named it: the viewer's Settings::for_scene applies it.
        scene.image = scene.image.then(&Overrides {
            quality: Some(preset),
            ..Overrides::default()
        });
    }
    whitted::viewer::run(scene)
}

fn scene_command(seed: u64) -> anyhow::Result<()> {
    use std::io::Write;
    let text = scene::hw3_toml(seed);
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        // A reader that stops early (`| head`) is not an error.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        result => result.context("cannot write the scene to standard output"),
    }
}

fn time_command(
    path: Option<&Path>,
    runs: usize,
    threads: Option<u32>,
    orbit: Option<u32>,
    preview: bool,
) -> anyhow::Result<()> {
    let scene = load_scene(path)?;
    let name = path.map_or("hw3".to_string(), |p| p.display().to_string());
    if let Some(views) = orbit {
        let size = (scene.settings().width, scene.settings().height);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.map_or(0, |t| t as usize))
            .build()
            .context("cannot start the threads")?;
        let timing =
            pool.install(|| whitted::speed::time_orbit(&scene, size, views as usize, preview))?;
        let line = timing.result_line(&name, pool.current_num_threads(), size);
        println!("{line}");
        return Ok(());
    }
    let mut opts = scene.settings();
    opts.threads = threads.map(|t| t as usize);
    let timing = whitted::speed::time_render(&scene, &opts, runs)?;
    println!("{}", timing.result_line(&name, &opts, scene.spheres.len()));
    Ok(())
}

fn render_command(args: RenderArgs) -> anyhow::Result<()> {
    let outputs: Vec<PathBuf> = if args.output.is_empty() {
        vec!["output.ppm".into(), "output.png".into()]
    } else {
        args.output.clone()
    };
    let mut targets = Vec::new();
    for path in outputs {
        // clap's parser has vetted every extension.
        let format = Format::from_path(&path, args.ppm_binary)?;
        // A folder we cannot write into fails now, not after a long render.
        image_io::check_writable(&path)?;
        targets.push((path, format));
    }

    let scene = load_scene(args.scene.as_deref())?;
    let opts = scene.settings().with(&args.overrides());
    opts.check()?;

    let control = Arc::new(RenderControl::default());
    {
        let control = Arc::clone(&control);
        ctrlc::set_handler(move || control.cancel())
            .context("cannot install the interrupt handler")?;
    }
    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let area = opts.area();
    let total = u64::from(area.width) * u64::from(area.height) * u64::from(opts.quality.spp);
    let progress = show_progress.then(|| spawn_progress(Arc::clone(&control), total));

    let result = render::render(&scene, &opts, &control);
    if let Some((done, handle)) = progress {
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        let _ = handle.join();
    }
    let (frame, stats) = result.map_err(|e| match e {
        render::RenderError::Cancelled => anyhow!("interrupted: no file was written"),
        other => anyhow!(other),
    })?;

    for (path, format) in &targets {
        if control.is_cancelled() {
            return Err(anyhow!(
                "interrupted: stopped before writing {}",
                path.display()
            ));
        }
        image_io::save(&frame, path, *format)?;
        if !args.quiet {
            eprintln!("wrote {}", path.display());
        }
    }
    if !args.quiet {
        eprintln!(
            "rendered {} {}x{} ({} spp, depth {}) in {:.3} s: {} rays, {:.1} Mrays/s",
            scene.name,
            area.width,
            area.height,
            opts.quality.spp,
            opts.quality.max_depth,
            stats.seconds,
            stats.rays.total(),
            stats.mrays_per_second()
        );
    }
    Ok(())
}

/// A progress bar on stderr that appears only once a render has run for a second.
fn spawn_progress(
    control: Arc<RenderControl>,
    total: u64,
) -> (
    Arc<std::sync::atomic::AtomicBool>,
    std::thread::JoinHandle<()>,
) {
    use std::sync::atomic::{AtomicBool, Ordering};
    let done = Arc::new(AtomicBool::new(false));
    let finished = Arc::clone(&done);
    let handle = std::thread::spawn(move || {
        let start = Instant::now();
        let mut bar: Option<indicatif::ProgressBar> = None;
        while !finished.load(Ordering::Relaxed) {
            std::thread::sleep(Duration::from_millis(50));
            if bar.is_none() && start.elapsed() > Duration::from_secs(1) {
                let b = indicatif::ProgressBar::new(total);
                b.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}",
                    )
                    .expect("a valid template"),
                );
                bar = Some(b);
            }
            if let Some(b) = &bar {
                b.set_position(control.pixels_done());
            }
        }
        if let Some(b) = bar {
            b.finish_and_clear();
        }
    });
    (done, handle)
}
