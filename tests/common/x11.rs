//! An Xvfb server, the viewer in it, and what the window tests do with them: real key
//! presses and mouse moves through `xdotool` (XTEST; winit ignores synthetic events),
//! screenshots through ImageMagick's `import`, renders of the same view by `whitted
//! render` to compare them with. Used by `viewer_x11.rs` and `viewer_soak.rs`.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use image::RgbImage;

pub const BIN: &str = env!("CARGO_BIN_EXE_whitted");
pub const TIMEOUT: Duration = Duration::from_secs(120);

pub fn have(tool: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(tool).is_file()))
}

/// Whether the X tools are installed. If not, `test` fails under `CI=true`; else it
/// is skipped, and a line says so on the harness's own stderr (not through
/// `eprintln!`, whose output the harness keeps to itself for a passing test).
pub fn x_tools_or_skip(test: &str) -> bool {
    let missing: Vec<&str> = ["Xvfb", "xdotool", "import"]
        .into_iter()
        .filter(|t| !have(t))
        .collect();
    if missing.is_empty() {
        return true;
    }
    let why = format!(
        "{} not installed (apt-get install xvfb xdotool imagemagick)",
        missing.join(", ")
    );
    super::skip(test, &why, "the viewer");
    false
}

/// Polls `f` until it gives a value or `TIMEOUT` passes.
pub fn wait_for<T>(what: &str, mut f: impl FnMut() -> Option<T>) -> T {
    poll(|| f().ok_or(())).unwrap_or_else(|()| panic!("timed out waiting for {what}"))
}

/// Polls `f` every 50 ms until it gives `Ok` or `TIMEOUT` passes; then the last `Err`.
fn poll<T, E>(mut f: impl FnMut() -> Result<T, E>) -> Result<T, E> {
    let start = Instant::now();
    loop {
        match f() {
            Ok(v) => return Ok(v),
            Err(last) if start.elapsed() >= TIMEOUT => return Err(last),
            Err(_) => std::thread::sleep(Duration::from_millis(50)),
        }
    }
}

/// An Xvfb server on a free display, killed on drop.
pub struct XServer {
    pub child: Child,
    pub display: String,
    pub runtime_dir: tempfile::TempDir,
    pub log: tempfile::NamedTempFile,
}

impl XServer {
    /// Starts Xvfb on a display number of its own. Not `-displayfd`: servers started
    /// at the same moment that way race for the same number, and the loser unlinks the
    /// winner's socket. Here each server of this process gets its own number from a
    /// range picked by the process id, skipping numbers whose lock file exists.
    pub fn start() -> XServer {
        XServer::start_with_screen(1280, 720)
    }

    /// [`XServer::start`] with a screen of `width`×`height`.
    pub fn start_with_screen(width: u32, height: u32) -> XServer {
        let screen = format!("{width}x{height}x24");
        use std::sync::atomic::{AtomicU32, Ordering};
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let base = 200 + (std::process::id() % 500) * 16;
        for _ in 0..16 {
            let number = base + NEXT.fetch_add(1, Ordering::Relaxed) % 16;
            if Path::new(&format!("/tmp/.X{number}-lock")).exists() {
                continue;
            }
            let log = tempfile::NamedTempFile::new().unwrap();
            let display = format!(":{number}");
            let child = Command::new("Xvfb")
                // No reset when the last client leaves: a server resetting refuses
                // connections for a moment, and the probe below is such a client. No
                // autorepeat: on a loaded machine `xdotool key` can be descheduled
                // between press and release for longer than the repeat delay.
                .args([
                    &display,
                    "-screen",
                    "0",
                    &screen,
                    "-nolisten",
                    "tcp",
                    "-noreset",
                    "-r",
                ])
                .stdout(Stdio::null())
                .stderr(Stdio::from(log.reopen().unwrap()))
                .spawn()
                .expect("Xvfb starts");
            let mut server = XServer {
                child,
                display,
                runtime_dir: tempfile::tempdir().unwrap(),
                log,
            };
            if server.wait_ready() {
                return server;
            }
        }
        panic!("could not start Xvfb on any of 16 display numbers from {base}");
    }

    /// Waits until clients can connect; false if the server gave up (number taken).
    pub fn wait_ready(&mut self) -> bool {
        let start = Instant::now();
        while start.elapsed() < TIMEOUT {
            if let Ok(Some(_)) = self.child.try_wait() {
                return false;
            }
            let probe = self
                .command("xdotool")
                .arg("getdisplaygeometry")
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status();
            if probe.is_ok_and(|s| s.success()) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        false
    }

    pub fn command(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY")
            .env("XDG_RUNTIME_DIR", self.runtime_dir.path());
        c
    }

    /// Runs an X client to completion.
    pub fn run(&self, program: &str, args: &[&str]) -> Output {
        self.command(program)
            .args(args)
            .output()
            .unwrap_or_else(|e| panic!("{program} runs: {e}"))
    }

    pub fn xdotool(&self, args: &[&str]) -> String {
        let out = self.run("xdotool", args);
        assert!(
            out.status.success(),
            "xdotool {args:?} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    }

    pub fn title(&self, window: &str) -> String {
        self.xdotool(&["getwindowname", window])
    }

    /// Waits until the window's title satisfies `ok`; returns it. A timeout says the
    /// last title seen and the viewer's stderr: where the viewer stopped.
    pub fn wait_title(
        &self,
        viewer: &mut Viewer,
        window: &str,
        ok: impl Fn(&str) -> bool,
    ) -> String {
        let title = poll(|| {
            viewer.assert_running();
            let title = self.title(window);
            if ok(&title) {
                Ok(title)
            } else {
                Err(title)
            }
        });
        title.unwrap_or_else(|last| {
            panic!(
                "timed out waiting for the window title; the last: {last:?}; the viewer's \
                 stderr:\n{}",
                viewer.stderr()
            )
        })
    }

    /// A screenshot of the window.
    pub fn screenshot(&self, window: &str, dir: &Path, name: &str) -> RgbImage {
        let path = dir.join(name);
        let out = self.run("import", &["-window", window, path.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "import failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        image::open(&path).expect("a screenshot").to_rgb8()
    }

    /// A real key press to the focused window.
    pub fn key(&self, window: &str, key: &str) {
        self.xdotool(&["windowfocus", "--sync", window]);
        self.xdotool(&["key", key]);
    }
}

impl XServer {
    /// The display's lock file and socket, which a server removes when it stops.
    pub fn files(&self) -> [PathBuf; 2] {
        let number = &self.display[1..];
        [
            PathBuf::from(format!("/tmp/.X{number}-lock")),
            PathBuf::from(format!("/tmp/.X11-unix/X{number}")),
        ]
    }
}

/// Stops the server with SIGTERM and waits for it, so that it removes its lock file
/// and socket; also when a test fails (a panic unwinds through here). SIGKILL only if
/// it has not stopped after 10 seconds.
impl Drop for XServer {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            // SAFETY: kill(2) on our own child, whose pid is not yet reaped.
            unsafe { libc::kill(self.child.id() as libc::pid_t, libc::SIGTERM) };
            let start = Instant::now();
            while let Ok(None) = self.child.try_wait() {
                if start.elapsed() > Duration::from_secs(10) {
                    let _ = self.child.kill();
                    break;
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        let _ = self.child.wait();
    }
}

/// The viewer process, killed on drop if still running.
pub struct Viewer {
    pub child: Child,
    pub stdout: PathBuf,
    pub stderr: PathBuf,
    /// What Xvfb said, for failures.
    pub xlog: String,
}

impl Viewer {
    pub fn stdout(&self) -> String {
        fs::read_to_string(&self.stdout).unwrap_or_default()
    }

    pub fn stderr(&self) -> String {
        fs::read_to_string(&self.stderr).unwrap_or_default()
    }

    pub fn assert_running(&mut self) {
        if let Ok(Some(status)) = self.child.try_wait() {
            panic!(
                "the viewer exited early with {status}; stderr:\n{}\nXvfb: {}",
                self.stderr(),
                self.xlog
            );
        }
    }

    pub fn wait_stdout(&mut self, needle: &str) {
        wait_for(&format!("`{needle}` on stdout"), || {
            self.assert_running();
            self.stdout().contains(needle).then_some(())
        })
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// `whitted render` of the scene, decoded.
pub fn headless(dir: &Path, scene: &Path, extra: &[&str], name: &str) -> RgbImage {
    let out_path = dir.join(name);
    let out = Command::new(BIN)
        .arg("render")
        .arg(scene)
        .arg("-o")
        .arg(&out_path)
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "render failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    image::open(&out_path).unwrap().to_rgb8()
}

/// The number of pixels that differ (images of different sizes differ everywhere).
pub fn differing(a: &RgbImage, b: &RgbImage) -> usize {
    if a.dimensions() != b.dimensions() {
        return (a.width() * a.height()).max(b.width() * b.height()) as usize;
    }
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

/// Screenshots until one equals `expected` (the last pass may still be on its way to
/// the screen when the title changes); returns the number of differing pixels of the
/// last screenshot.
pub fn screenshot_matching(x: &XServer, window: &str, dir: &Path, expected: &RgbImage) -> usize {
    let mut diff = usize::MAX;
    for attempt in 0..20 {
        let shot = x.screenshot(window, dir, &format!("shot-{attempt}.png"));
        diff = differing(&shot, expected);
        if diff == 0 {
            break;
        }
        std::thread::sleep(Duration::from_millis(250));
    }
    diff
}

/// Starts `whitted view SCENE` in `dir` with `env` and `WHITTED_STATS=1`, its output
/// to `viewer.out` and `viewer.err` there; returns it and its window, found by the
/// scene's name (the file stem) in the title.
pub fn start_viewer_with(
    x: &XServer,
    dir: &Path,
    scene: &Path,
    env: &[(&str, &str)],
) -> (Viewer, String) {
    let name = scene.file_stem().unwrap().to_string_lossy();
    let title = format!("^whitted - {name} - ");
    let stdout = dir.join("viewer.out");
    let stderr = dir.join("viewer.err");
    let child = x
        .command(BIN)
        .arg("view")
        .arg(scene)
        .current_dir(dir)
        .envs(env.iter().copied())
        .env("WHITTED_STATS", "1")
        .stdin(Stdio::null())
        .stdout(fs::File::create(&stdout).unwrap())
        .stderr(fs::File::create(&stderr).unwrap())
        .spawn()
        .expect("the viewer starts");
    let xlog = format!(
        "display {}, log {}: {}",
        x.display,
        x.log.path().display(),
        fs::read_to_string(x.log.path()).unwrap_or_default()
    );
    let mut viewer = Viewer {
        child,
        stdout,
        stderr,
        xlog,
    };
    let window = wait_for("the window", || {
        viewer.assert_running();
        let out = x.run("xdotool", &["search", "--onlyvisible", "--name", &title]);
        let id = String::from_utf8_lossy(&out.stdout);
        id.lines().next().map(str::to_string)
    });
    (viewer, window)
}
