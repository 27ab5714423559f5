//! The subcommands of the `whitted` binary, one module each; the library does the work.

pub(crate) mod animate;
pub(crate) mod bench;
pub(crate) mod compare;
pub(crate) mod render;
pub(crate) mod stitch;

use std::path::{Path, PathBuf};

use anyhow::Context;

use whitted::scene::{self, Scene};
use whitted::settings::Overrides;

/// An option's value that the command line cannot honour (a frame the scene lacks,
/// a region outside the image): a usage error like clap's own, exit status 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct UsageError(pub(crate) String);

/// A [`UsageError`] saying `message`.
pub(crate) fn usage(message: String) -> anyhow::Error {
    anyhow::Error::new(UsageError(message))
}

/// Whether `e` is a usage error (exit status 2): a [`UsageError`], or settings from
/// the command line that [`whitted::settings::Settings::check`] refuses (the scene
/// file's own settings are checked, with their place, when it loads).
pub(crate) fn is_usage_error(e: &anyhow::Error) -> bool {
    e.downcast_ref::<UsageError>().is_some()
        || e.downcast_ref::<whitted::settings::SettingsError>()
            .is_some()
}

/// The parser of a whole-number option from `lo` to `hi` whose error says what is
/// wanted ("expected a whole number from 1 to 65536"), also for a negative number
/// (which clap would otherwise take for an unknown option).
pub(crate) fn whole_number(lo: u32, hi: u32) -> impl Fn(&str) -> Result<u32, String> + Clone {
    move |text| match text.trim().parse::<i128>() {
        Ok(n) if (i128::from(lo)..=i128::from(hi)).contains(&n) => Ok(n as u32),
        _ => Err(format!("expected a whole number from {lo} to {hi}")),
    }
}

/// On Ctrl-C, SIGTERM or SIGHUP: interrupts the writing of files (none is put in
/// place any more) and calls `stop` (which cancels the render, or closes the window),
/// so that the command ends with exit status 1 and leaves no partial file; files
/// complete before the signal stay.
pub(crate) fn stop_on_signals(stop: impl Fn() + Send + 'static) -> anyhow::Result<()> {
    ctrlc::set_handler(move || {
        whitted::image_io::interrupt_writes();
        stop();
    })
    .context("cannot install the interrupt handler")
}

/// A `stop` for [`stop_on_signals`] that cancels `control`: the render stops within
/// a row of pixels.
pub(crate) fn cancel(
    control: &std::sync::Arc<whitted::render::RenderControl>,
) -> impl Fn() + Send + 'static {
    let control = std::sync::Arc::clone(control);
    move || control.cancel()
}

/// The built-in scene, embedded from the file the generator wrote
/// (`whitted scene hw3 > assets/scenes/hw3.toml`); a test keeps the two in step.
pub(crate) const BUILTIN_SCENE: &str = include_str!("../../assets/scenes/hw3.toml");

pub(crate) fn builtin_scene() -> anyhow::Result<Scene> {
    let mut scene = Scene::from_toml_str(BUILTIN_SCENE, "assets/scenes/hw3.toml")
        .context("the built-in scene is broken")?;
    scene.name = "hw3".into();
    Ok(scene)
}

pub(crate) fn load_scene(path: Option<&Path>) -> anyhow::Result<Scene> {
    match path {
        None => builtin_scene(),
        Some(p) => Ok(Scene::load(p)?),
    }
}

/// The viewer on the scene at `path`, with `options` (the command line's) over the
/// scene file's settings, as if the file gave them.
pub(crate) fn view(path: Option<&Path>, options: Overrides) -> anyhow::Result<()> {
    let mut scene = load_scene(path)?;
    scene.image = scene.image.then(&options);
    return_large_blocks();
    whitted::viewer::run(
        scene,
        whitted::viewer::Host {
            on_open: Box::new(|stop| stop_on_signals(move || stop.stop())),
            release_memory,
        },
    )
}

/// Gives glibc's free memory back to the system (see
/// [`whitted::viewer::Host::release_memory`]).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn release_memory() {
    // SAFETY: malloc_trim takes no pointers; glibc locks each arena while it trims it.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Other allocators give large freed blocks back themselves.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn release_memory() {}

/// glibc's malloc with its thresholds fixed at their defaults (128 KiB): every block
/// from 128 KiB is mapped on its own and unmapped when freed, and a thread's heap
/// gives back what is free above 128 KiB. Left to itself, glibc raises both to the
/// largest block freed (the viewer frees frames of up to 44 MB), and `malloc_trim`
/// cannot shrink the top of a thread's heap: the idle window at 640x360 then held
/// 7 to 37 MiB depending on the sizes before (docs/log.md, 2026-12-02).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn return_large_blocks() {
    const THRESHOLD: libc::c_int = 128 * 1024;
    // SAFETY: mallopt takes no pointers; it sets two of glibc's numbers.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, THRESHOLD);
        libc::mallopt(libc::M_TRIM_THRESHOLD, THRESHOLD);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn return_large_blocks() {}

/// glibc's malloc for a render that runs once and exits: every block comes from the
/// heap (none is mapped on its own, whatever its size), nothing is given back to the
/// system before the exit, and all threads share one arena. The memory the load frees
/// (the file's text, its tables) is then what the build and the frame take, not fresh
/// pages, which the kernel maps and zeroes one fault at a time (about 2 µs a page on
/// the 2-core machine of docs/speed.md; the build of a million spheres touched
/// 118,000 of them when blocks over 32 MiB were mapped apart, 38,000 now).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub(crate) fn keep_freed_blocks() {
    // SAFETY: mallopt takes no pointers; it sets three of glibc's numbers.
    unsafe {
        libc::mallopt(libc::M_MMAP_MAX, 0);
        libc::mallopt(libc::M_TRIM_THRESHOLD, libc::c_int::MAX);
        libc::mallopt(libc::M_ARENA_MAX, 1);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub(crate) fn keep_freed_blocks() {}

pub(crate) fn scene_command(seed: u64) -> anyhow::Result<()> {
    use std::io::Write;
    let text = scene::hw3_toml(seed);
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        // A reader that stops early (`| head`) is not an error.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        result => result.context("cannot write the scene to standard output"),
    }
}

/// What `whitted time --orbit` times: `views` views, previews as the window chooses
/// them or none, each view's scene written into `views_to` if given.
pub(crate) struct Orbit {
    pub(crate) views: u32,
    pub(crate) preview: bool,
    pub(crate) views_to: Option<PathBuf>,
}

pub(crate) fn time_command(
    path: Option<&Path>,
    runs: usize,
    threads: Option<u32>,
    orbit: Option<Orbit>,
) -> anyhow::Result<()> {
    let scene = load_scene(path)?;
    let name = path.map_or("hw3".to_string(), |p| p.display().to_string());
    if let Some(Orbit {
        views,
        preview,
        views_to,
    }) = orbit
    {
        let size = (scene.settings().width, scene.settings().height);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.map_or(0, |t| t as usize))
            .build()
            .context("cannot start the threads")?;
        let timing = pool.install(|| {
            whitted::speed::time_orbit(&scene, size, views as usize, preview, views_to.as_deref())
        })?;
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

/// A progress bar on stderr that appears once the work has run for a second (shorter
/// work shows none), its clock counting from the start.
pub(crate) struct Progress {
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
    thread: std::thread::JoinHandle<()>,
}

impl Progress {
    /// Starts watching: `at` gives the work done and the work in all, `template` is
    /// indicatif's.
    pub(crate) fn start(
        template: &'static str,
        at: impl Fn() -> (u64, u64) + Send + 'static,
    ) -> Progress {
        use std::sync::atomic::{AtomicBool, Ordering};
        use std::time::{Duration, Instant};
        let stop = std::sync::Arc::new(AtomicBool::new(false));
        let stopped = std::sync::Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            let start = Instant::now();
            let mut bar: Option<indicatif::ProgressBar> = None;
            while !stopped.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(50));
                let (done, total) = at();
                if bar.is_none() && start.elapsed() > Duration::from_secs(1) {
                    let b = indicatif::ProgressBar::new(total).with_elapsed(start.elapsed());
                    b.set_style(
                        indicatif::ProgressStyle::with_template(template)
                            .expect("a valid template"),
                    );
                    bar = Some(b);
                }
                if let Some(b) = &bar {
                    b.set_length(total.max(1));
                    b.set_position(done);
                }
            }
            if let Some(b) = bar {
                b.finish_and_clear();
            }
        });
        Progress { stop, thread }
    }

    /// Stops and clears the bar.
    pub(crate) fn finish(self) {
        self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        let _ = self.thread.join();
    }
}
