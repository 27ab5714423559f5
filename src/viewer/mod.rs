//! The window (SPEC §6): winit for the window and input, `pixels` or `softbuffer` to
//! show the image. This file is only the event loop; the parts with logic live in
//! small modules tested without a window: [`controls`] (camera maths), [`schedule`]
//! (progressive passes), [`worker`] (the render thread), [`buffer`] (the flip of the
//! bottom-up frame into top-down screen bytes), [`save`] (numbered files),
//! [`inspect`] (the pixel inspector) and [`status`] (title, keys, timings).
//!
//! The event loop never renders: it submits a job per view to the worker, which sends
//! each finished pass back as a user event; the loop copies it to the window.

pub mod blit;
pub mod buffer;
pub mod controls;
pub mod inspect;
pub mod lattice;
pub mod save;
pub mod schedule;
pub mod status;
pub mod worker;

use std::path::Path;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::scene::Scene;

use blit::{Blitter, Choice};
use controls::{Action, CameraControl};
use status::Progress;
use worker::{Report, Shown, Worker};

/// A press and release closer than this (pixels) is a click, not a drag.
const CLICK_SLOP: f64 = 3.0;

/// What wakes the event loop besides the window's own events.
enum Wake {
    /// A finished pass, or a failed render, from the worker.
    Report(Report),
    /// [`Stop::stop`]: close the window.
    Stop,
}

/// Closes the window from any thread (a signal handler's): the viewer stops, waits
/// for the saves in flight, and [`run`] returns [`Interrupted`].
#[derive(Clone)]
pub struct Stop(EventLoopProxy<Wake>);

impl Stop {
    pub fn stop(&self) {
        // After the loop has closed there is nothing left to stop.
        let _ = self.0.send_event(Wake::Stop);
    }
}

/// The viewer was closed by [`Stop::stop`].
#[derive(Debug, thiserror::Error)]
#[error("interrupted")]
pub struct Interrupted;

/// What the program that opens the window lends it.
pub struct Host {
    /// Called before the window opens, with a handle that closes it (the command line
    /// hands it to its signal handler).
    pub on_open: Box<dyn FnOnce(Stop) -> anyhow::Result<()>>,
    /// Called when a view is complete: gives the memory the views freed back to the
    /// system (the command line calls glibc's `malloc_trim`, which frees the unused
    /// pages inside the arenas of rayon's threads).
    pub release_memory: fn(),
}

/// Opens the viewer on `scene` and returns when the window closes.
pub fn run(scene: Scene, host: Host) -> anyhow::Result<()> {
    let started = Instant::now();
    let choice = blit::parse_choice(std::env::var("WHITTED_BLIT").ok().as_deref())
        .map_err(|e| anyhow!(e))?;
    let stats = status::stats_enabled(std::env::var("WHITTED_STATS").ok().as_deref());
    let has_display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    let hint = "use `whitted render` to write the image to files instead";
    if !has_display {
        bail!("no display to open a window on (DISPLAY and WAYLAND_DISPLAY are unset); {hint}");
    }
    let _runtime_dir = quiet_wayland_probe();
    let event_loop = EventLoop::<Wake>::with_user_event()
        .build()
        .map_err(|e| anyhow!("cannot open the display ({}); {hint}", winit_message(&e)))?;
    event_loop.set_control_flow(ControlFlow::Wait);
    (host.on_open)(Stop(event_loop.create_proxy()))?;
    let proxy = event_loop.create_proxy();
    let mut app = App::new(scene, proxy, choice, stats, started, host.release_memory);
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    app.finish()
}

/// Without Wayland (no `WAYLAND_DISPLAY`) and without a valid `XDG_RUNTIME_DIR`, points
/// `XDG_RUNTIME_DIR` at a private empty folder for the life of the window (the
/// returned guard removes it). Mesa's Vulkan device-select layer looks for a Wayland
/// display whenever wgpu asks for Wayland surfaces, and libwayland prints "error:
/// XDG_RUNTIME_DIR is invalid or not set in the environment." twice when that
/// variable is missing, although the window (on X11) works. In an empty folder the
/// probe finds no display and says nothing. Runs before any thread is started.
fn quiet_wayland_probe() -> Option<tempfile::TempDir> {
    let set = |v: &str| std::env::var_os(v).filter(|s| !s.is_empty());
    let runtime_ok = set("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_absolute());
    if set("WAYLAND_DISPLAY").is_some() || runtime_ok {
        return None;
    }
    let dir = tempfile::Builder::new()
        .prefix("whitted-runtime-")
        .tempdir()
        .ok()?;
    std::env::set_var("XDG_RUNTIME_DIR", dir.path());
    Some(dir)
}

/// winit's error without the source location it prefixes to OS errors.
fn winit_message(e: &dyn std::fmt::Display) -> String {
    let text = e.to_string();
    match text.split_once(": ") {
        Some((location, message)) if location.starts_with("os error at ") => message.into(),
        _ => text,
    }
}

struct Drag {
    start: (f64, f64),
    last: (f64, f64),
    moved: bool,
}

struct App {
    scene: Arc<Scene>,
    stem: String,
    choice: Choice,
    stats: bool,
    started: Instant,
    window: Option<Arc<Window>>,
    blitter: Option<Blitter>,
    worker: Worker,
    camera: CameraControl,
    /// The window's inner size (0×0 when minimised).
    size: (u32, u32),
    /// The size and scene (with the view's camera) of the current job.
    job_size: (u32, u32),
    job_scene: Arc<Scene>,
    generation: u64,
    progress: Progress,
    /// What is on screen, and the scene it was rendered from.
    shown: Option<(Shown, Arc<Scene>)>,
    /// A new frame waits to be drawn.
    fresh: bool,
    cursor: Option<(f64, f64)>,
    drag: Option<Drag>,
    numbering: save::Numbering,
    saves: Vec<JoinHandle<()>>,
    inspector: inspect::Inspector,
    first_frame_reported: bool,
    /// Holds camera changes while the current view has nothing on screen.
    throttle: schedule::Throttle,
    /// Pixels per second of the last one-sample pass, to size the next preview.
    speed: f64,
    error: Option<anyhow::Error>,
    /// The animation frame rendered (0 for a still scene).
    frame: u32,
    /// The frame of the current job, and of what is on screen.
    job_frame: u32,
    shown_frame: u32,
    /// `P`: the frames advance by themselves.
    playing: bool,
    /// When the current job was submitted: the next frame is due 1/fps after it.
    job_started: Instant,
    /// Playing, the current frame is complete and the next is due at this time.
    next_frame_at: Option<Instant>,
    /// See [`Host::release_memory`].
    release_memory: fn(),
}

impl App {
    fn new(
        scene: Scene,
        proxy: EventLoopProxy<Wake>,
        choice: Choice,
        stats: bool,
        started: Instant,
        release_memory: fn(),
    ) -> App {
        let scene = Arc::new(scene);
        // The proxy wakes the event loop; after it has closed, reports are dropped.
        let worker = Worker::spawn(move |report| {
            let _ = proxy.send_event(Wake::Report(report));
        });
        App {
            stem: save::file_stem(&scene.name),
            camera: CameraControl::new(&scene),
            job_scene: Arc::clone(&scene),
            scene,
            choice,
            stats,
            started,
            window: None,
            blitter: None,
            worker,
            size: (0, 0),
            job_size: (0, 0),
            generation: 0,
            progress: Progress::Rendering,
            shown: None,
            fresh: false,
            cursor: None,
            drag: None,
            numbering: save::Numbering::default(),
            saves: Vec::new(),
            inspector: inspect::Inspector::spawn(),
            first_frame_reported: false,
            throttle: schedule::Throttle::default(),
            speed: f64::NAN,
            error: None,
            frame: 0,
            job_frame: 0,
            shown_frame: 0,
            playing: false,
            job_started: started,
            next_frame_at: None,
            release_memory,
        }
    }

    /// After the loop: waits for saves in flight, returns the error that ended it.
    fn finish(mut self) -> anyhow::Result<()> {
        self.worker.cancel();
        for save in self.saves.drain(..) {
            let _ = save.join();
        }
        match self.error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.error = Some(error);
        event_loop.exit();
    }

    /// Renders the current camera at the window size (unless minimised).
    fn submit(&mut self) {
        let (w, h) = self.size;
        if w == 0 || h == 0 {
            return;
        }
        self.generation += 1;
        self.throttle.started();
        let mut scene = (*self.scene).clone();
        let still = self.camera.spec(&self.scene, w, h);
        // The animation moves the scene's camera, not one the user has edited.
        scene.camera = Some(match &self.scene.animation {
            Some(animation) if !self.camera.is_edited() => animation.camera_at(&still, self.frame),
            _ => still,
        });
        self.job_scene = Arc::new(scene);
        self.job_frame = self.frame;
        self.job_started = Instant::now();
        self.next_frame_at = None;
        self.job_size = (w, h);
        self.progress = Progress::Rendering;
        let factor = schedule::preview_factor(w, h, self.speed);
        self.worker
            .submit(self.generation, Arc::clone(&self.job_scene), (w, h), factor);
        self.update_title();
    }

    fn update_title(&self) {
        if let Some(window) = &self.window {
            let (w, h) = self.job_size;
            let frame = self.frame_label(self.job_frame);
            let title = status::title_of_frame(&self.scene.name, w, h, frame, &self.progress);
            window.set_title(&title);
        }
    }

    /// `(k, frames)` for the title of an animated scene.
    fn frame_label(&self, k: u32) -> Option<(u32, u32)> {
        self.scene.animation.as_ref().map(|a| (k, a.frames))
    }

    /// Shows frame `k` (wrapping around the animation).
    fn go_to_frame(&mut self, k: i64) {
        let frames = i64::from(self.scene.frames());
        self.frame = k.rem_euclid(frames) as u32;
        self.submit();
    }

    /// `,` and `.`: one frame back or forward; stepping pauses.
    fn step(&mut self, by: i64) {
        if self.scene.animation.is_some() {
            self.playing = false;
            self.go_to_frame(i64::from(self.frame) + by);
        }
    }

    /// `P`: plays from the frame on screen, or pauses.
    fn toggle_play(&mut self) {
        if self.scene.animation.is_none() {
            println!("this scene has no animation to play");
            return;
        }
        self.playing = !self.playing;
        self.next_frame_at = None;
        if self.playing
            && matches!(self.progress, Progress::Samples { samples, target, .. } if samples >= target)
        {
            self.go_to_frame(i64::from(self.frame) + 1);
        }
    }

    /// Playing, once a frame is complete: the next is due 1/fps after this one
    /// started, or at once if rendering took longer.
    fn schedule_next_frame(&mut self) {
        let Some(animation) = &self.scene.animation else {
            return;
        };
        let period = Duration::from_secs_f64(1.0 / animation.fps);
        self.next_frame_at = Some(self.job_started + period);
    }

    fn camera_action(&mut self, action: Action) {
        let (w, h) = self.job_size;
        if w > 0 && self.camera.apply(&self.scene, w, h, action) && self.throttle.changed() {
            self.submit();
        }
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, event: &KeyEvent) {
        if event.state != ElementState::Pressed {
            return;
        }
        match &event.logical_key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Named(NamedKey::ArrowUp) => self.camera_action(Action::Forward(1.0)),
            Key::Named(NamedKey::ArrowDown) => self.camera_action(Action::Forward(-1.0)),
            Key::Named(NamedKey::ArrowLeft) => self.camera_action(Action::Right(-1.0)),
            Key::Named(NamedKey::ArrowRight) => self.camera_action(Action::Right(1.0)),
            Key::Named(NamedKey::PageUp) => self.camera_action(Action::Lift(1.0)),
            Key::Named(NamedKey::PageDown) => self.camera_action(Action::Lift(-1.0)),
            Key::Character(c) => match c.to_ascii_lowercase().as_str() {
                "q" => event_loop.exit(),
                "s" if !event.repeat => self.save(),
                "r" if self.camera.is_edited() => {
                    self.camera.reset();
                    self.submit();
                }
                "h" => println!("{}", status::HELP),
                "p" if !event.repeat => self.toggle_play(),
                "," => self.step(-1),
                "." => self.step(1),
                _ => {}
            },
            _ => {}
        }
    }

    /// Saves what is on screen under new numbered names, on a thread of its own.
    fn save(&mut self) {
        let Some((shown, scene)) = &self.shown else {
            println!("nothing on screen to save yet");
            return;
        };
        let frame = Arc::clone(&shown.frame);
        let encoding = scene.settings().encoding;
        let mut what = format!(
            "{}x{}, {}/{} spp",
            frame.width, frame.height, shown.samples, shown.target
        );
        if let Some((k, n)) = self.frame_label(self.shown_frame) {
            what += &format!(", frame {k}/{n}");
        }
        // The view's camera as a scene file states it: `whitted render` with it (and
        // this size) renders these pixels again.
        let camera = scene
            .camera
            .map(|spec| format!("; camera = {}", crate::scene::camera_to_toml(&spec)))
            .unwrap_or_default();
        let (png, ppm) = self
            .numbering
            .next(Path::new(""), &self.stem, |p| p.exists());
        // Finished saves are joined: a thread not joined keeps its stack.
        self.saves.retain(|save| !save.is_finished());
        self.saves.push(std::thread::spawn(move || {
            match save::save_pair(&frame, &png, &ppm, encoding) {
                Ok(()) => println!(
                    "saved {} and {} ({what}){camera}",
                    png.display(),
                    ppm.display()
                ),
                Err(e) => eprintln!("whitted: cannot save: {e}"),
            }
        }));
    }

    /// Prints the ray tree of the pixel under the cursor (on the inspector's thread).
    fn inspect(&self, position: (f64, f64)) {
        let (Some((shown, scene)), Some(blitter)) = (&self.shown, &self.blitter) else {
            return;
        };
        let size = (shown.frame.width, shown.frame.height);
        let Some((i, j)) = blitter.pixel_at(position, size, self.size) else {
            return;
        };
        self.inspector.inspect(inspect::Request {
            scene: Arc::clone(scene),
            size,
            pixel: (i, j),
            shown: shown.frame.get(i, j),
        });
    }

    fn frame_ready(&mut self, shown: Shown) {
        if shown.generation != self.generation {
            return; // a stale pass of a cancelled view
        }
        if let Some(speed) =
            schedule::measured_speed(shown.samples, shown.pass_pixels, shown.pass_seconds)
        {
            self.speed = speed;
        }
        self.progress = if shown.preview {
            Progress::Preview {
                seconds: shown.pass_seconds,
            }
        } else {
            Progress::Samples {
                samples: shown.samples,
                target: shown.target,
                seconds: shown.pass_seconds,
            }
        };
        let complete = shown.done;
        // The frames of the passes before this one are freed here.
        self.shown = Some((shown, Arc::clone(&self.job_scene)));
        if complete {
            (self.release_memory)();
        }
        self.shown_frame = self.job_frame;
        self.fresh = true;
        if complete && self.playing {
            self.schedule_next_frame();
        }
        if let Some(window) = &self.window {
            window.request_redraw();
        }
        if self.throttle.shown() {
            self.submit();
        }
    }

    fn redraw(&mut self) {
        let (Some(blitter), Some((shown, _))) = (&mut self.blitter, &self.shown) else {
            return;
        };
        if self.size.0 == 0 || self.size.1 == 0 {
            return;
        }
        let start = Instant::now();
        let (w, h) = (shown.frame.width, shown.frame.height);
        if let Err(e) = blitter.draw(&shown.rgba, w, h) {
            eprintln!("whitted: {e}");
        }
        let blit = start.elapsed().as_secs_f64();
        if self.fresh {
            self.fresh = false;
            // The title changes only once the frame it describes is on screen, so a
            // title ending in "done" means the window shows the finished image.
            self.update_title();
            if self.stats {
                self.print_stats(blit);
            }
        }
    }

    fn print_stats(&mut self, blit: f64) {
        let Some((shown, _)) = &self.shown else {
            return;
        };
        let kind = if shown.preview { "preview" } else { "samples" };
        eprintln!(
            "stats: view {} {} {}x{} pass_pixels {} spp {}/{} render_ms {:.2} blit_ms {:.2} since_view_ms {:.2} since_start_ms {:.2}",
            shown.generation,
            kind,
            shown.frame.width,
            shown.frame.height,
            shown.pass_pixels,
            shown.samples,
            shown.target,
            shown.pass_seconds * 1e3,
            blit * 1e3,
            shown.since_submit * 1e3,
            self.started.elapsed().as_secs_f64() * 1e3,
        );
        if !self.first_frame_reported {
            self.first_frame_reported = true;
            let blitter = self.blitter.as_ref().map_or("none", Blitter::name);
            eprintln!("stats: blitter {blitter}");
            if let Some(adapter) = self.blitter.as_ref().and_then(Blitter::adapter) {
                eprintln!("stats: adapter {adapter}");
            }
        }
    }
}

impl ApplicationHandler<Wake> for App {
    /// Playing: waits (without blocking the loop) until the next frame is due.
    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        match self.next_frame_at {
            Some(due) if Instant::now() >= due => {
                // Due once: a minimised window submits nothing, so the frame must
                // not advance again on the next event.
                self.next_frame_at = None;
                self.go_to_frame(i64::from(self.frame) + 1);
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Some(due) => event_loop.set_control_flow(ControlFlow::WaitUntil(due)),
            None => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }

    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let (w, h) = (self.scene.settings().width, self.scene.settings().height);
        let attributes = Window::default_attributes()
            .with_title(status::title_of_frame(
                &self.scene.name,
                w,
                h,
                self.frame_label(0),
                &Progress::Rendering,
            ))
            .with_inner_size(PhysicalSize::new(w, h));
        let window = match event_loop.create_window(attributes) {
            Ok(window) => Arc::new(window),
            Err(e) => {
                return self.fail(event_loop, anyhow!("cannot open a window: {e}"));
            }
        };
        let inner = window.inner_size();
        self.size = (inner.width, inner.height);
        let surface = if self.size.0 == 0 || self.size.1 == 0 {
            (w, h)
        } else {
            self.size
        };
        self.window = Some(Arc::clone(&window));
        // Render while the blitter starts up (wgpu takes a while to find its adapter).
        self.submit();
        match Blitter::new(&window, surface, self.choice) {
            Ok(blitter) => self.blitter = Some(blitter),
            Err(e) => self.fail(event_loop, anyhow!(e)),
        }
    }

    fn user_event(&mut self, event_loop: &ActiveEventLoop, wake: Wake) {
        match wake {
            Wake::Stop => self.fail(event_loop, Interrupted.into()),
            Wake::Report(Report::Frame(shown)) => self.frame_ready(shown),
            Wake::Report(Report::Failed {
                generation,
                message,
            }) => {
                if generation == self.generation {
                    eprintln!("whitted: cannot render this view: {message}");
                    self.progress = Progress::Failed;
                    self.update_title();
                    if self.throttle.shown() {
                        self.submit();
                    }
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::RedrawRequested => self.redraw(),
            WindowEvent::Resized(size) => {
                self.size = (size.width, size.height);
                if size.width == 0 || size.height == 0 {
                    return; // minimised: keep everything until it comes back
                }
                if let Some(blitter) = &mut self.blitter {
                    if let Err(e) = blitter.resize_surface(self.size) {
                        eprintln!("whitted: {e}");
                    }
                }
                if self.size != self.job_size {
                    self.submit();
                }
                if let Some(window) = &self.window {
                    window.request_redraw();
                }
            }
            // A synthetic press is a key already down as the window gains focus: not
            // pressed for this window, so it does nothing.
            WindowEvent::KeyboardInput {
                event,
                is_synthetic: false,
                ..
            } => self.key(event_loop, &event),
            WindowEvent::CursorMoved { position, .. } => {
                let now = (position.x, position.y);
                self.cursor = Some(now);
                if let Some(drag) = &mut self.drag {
                    let (dx, dy) = (now.0 - drag.last.0, now.1 - drag.last.1);
                    let far = (now.0 - drag.start.0).hypot(now.1 - drag.start.1);
                    drag.moved |= far > CLICK_SLOP;
                    if drag.moved {
                        drag.last = now;
                        let height = self.job_size.1;
                        self.camera_action(Action::Drag { dx, dy, height });
                    }
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => match state {
                ElementState::Pressed => {
                    if let Some(at) = self.cursor {
                        self.drag = Some(Drag {
                            start: at,
                            last: at,
                            moved: false,
                        });
                    }
                }
                ElementState::Released => {
                    if let Some(drag) = self.drag.take() {
                        if !drag.moved {
                            self.inspect(drag.start);
                        }
                    }
                }
            },
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                if steps != 0.0 {
                    self.camera_action(Action::Zoom(steps));
                }
            }
            _ => {}
        }
    }
}
