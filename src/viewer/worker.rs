//! The render thread. The window submits a job per view (camera and size); the worker
//! runs its passes ([`plan`]) through the library's renderer (on rayon's threads) and
//! reports each finished pass through a callback, which in the window wakes the event
//! loop. A new job cancels the running one through its [`RenderControl`], so stale
//! work stops within a row of pixels; the worker then skips to the newest job.

use std::collections::VecDeque;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

use glam::Vec3;

use crate::render::{self, Frame, RenderControl, RenderError};
use crate::scene::Scene;
use crate::settings::{Precision, Settings};
use crate::trace::fast::FastTracer;
use crate::trace::SampleTracer;

use super::buffer::{fill_for_screen, fill_upscaled_for_screen, resize_buffer, ScreenRows};
use super::lattice::{self, Lattice};
use super::schedule::{plan, Pass};

/// One view to render: the scene (its camera is the view's), at this size.
pub struct Job {
    pub generation: u64,
    pub scene: Arc<Scene>,
    pub width: u32,
    pub height: u32,
    /// The preview's size is 1/`preview_factor` of the view's.
    pub preview_factor: u32,
    control: Arc<RenderControl>,
    submitted: Instant,
}

/// A finished pass, ready to show.
#[derive(Clone, Debug)]
pub struct Shown {
    pub generation: u64,
    /// Linear RGB at the full size of the job (a preview is scaled up), row 0 at the
    /// bottom: what `S` saves.
    pub frame: Arc<Frame>,
    /// The same, as top-down RGBA bytes: what the window shows.
    pub rgba: Arc<Vec<u8>>,
    /// Samples per pixel so far (0 for the preview).
    pub samples: u32,
    /// The target samples per pixel.
    pub target: u32,
    pub preview: bool,
    /// The number of pixels rendered in this pass (the preview's are fewer).
    pub pass_pixels: u64,
    /// The last pass: the image is complete.
    pub done: bool,
    /// Time this pass took.
    pub pass_seconds: f64,
    /// Time since the job was submitted.
    pub since_submit: f64,
}

impl Job {
    /// A view to render at `width`×`height`, with its preview at 1/`preview_factor`
    /// of the size.
    pub fn new(
        generation: u64,
        scene: Arc<Scene>,
        (width, height): (u32, u32),
        preview_factor: u32,
    ) -> Job {
        Job {
            generation,
            scene,
            width,
            height,
            preview_factor,
            control: Arc::new(RenderControl::default()),
            submitted: Instant::now(),
        }
    }
}

pub enum Report {
    Frame(Shown),
    Failed { generation: u64, message: String },
}

/// The handle the window keeps: submits jobs, cancels stale ones.
pub struct Worker {
    jobs: Option<Sender<Job>>,
    current: Option<Arc<RenderControl>>,
    thread: Option<JoinHandle<()>>,
}

impl Worker {
    /// Starts the render thread; `sink` receives every report (from that thread).
    pub fn spawn(sink: impl Fn(Report) + Send + 'static) -> Worker {
        let (tx, rx) = mpsc::channel::<Job>();
        let thread = std::thread::Builder::new()
            .name("whitted-render".into())
            .spawn(move || serve(rx, sink))
            .expect("cannot start the render thread");
        Worker {
            jobs: Some(tx),
            current: None,
            thread: Some(thread),
        }
    }

    /// Cancels the running job and queues this one.
    pub fn submit(
        &mut self,
        generation: u64,
        scene: Arc<Scene>,
        (width, height): (u32, u32),
        preview_factor: u32,
    ) {
        self.cancel();
        let job = Job::new(generation, scene, (width, height), preview_factor);
        self.current = Some(Arc::clone(&job.control));
        if let Some(jobs) = &self.jobs {
            // The thread only ends when this sender is dropped, so this cannot fail
            // unless it panicked; then there is nothing better to do than not render.
            let _ = jobs.send(job);
        }
    }

    /// Stops the running job (if any).
    pub fn cancel(&mut self) {
        if let Some(control) = self.current.take() {
            control.cancel();
        }
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.cancel();
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn serve(rx: Receiver<Job>, sink: impl Fn(Report)) {
    let mut cache = TracerCache::default();
    let mut buffers = Buffers::default();
    while let Ok(mut job) = rx.recv() {
        // Only the newest queued view matters.
        while let Ok(newer) = rx.try_recv() {
            job = newer;
        }
        match run(&job, &mut cache, &mut buffers, &sink) {
            Ok(()) | Err(RenderError::Cancelled) => {}
            Err(e) => sink(Report::Failed {
                generation: job.generation,
                message: e.to_string(),
            }),
        }
    }
}

/// The last view's tracer: a new view of the same scene reuses its compiled scene and
/// rebuilds only the camera's part (see `FastTracer::with_camera`).
#[derive(Default)]
pub struct TracerCache {
    last: Option<(Arc<Scene>, FastTracer)>,
    /// How many times a scene was compiled (hierarchy, lights' grids) from scratch.
    pub compiles: u64,
}

impl TracerCache {
    fn tracer(&mut self, scene: &Arc<Scene>, opts: &Settings) -> Result<&FastTracer, RenderError> {
        let camera = scene.camera(opts.width, opts.height)?;
        let depth = opts.quality.max_depth;
        let tracer = match self.last.take() {
            Some((s, previous)) if same_contents(&s, scene) => previous.with_camera(&camera, depth),
            _ => {
                self.compiles += 1;
                FastTracer::new(scene, &camera, depth)
            }
        }
        .with_cutoff(opts.quality.cutoff);
        Ok(&self.last.insert((Arc::clone(scene), tracer)).1)
    }
}

/// Whether two scenes compile alike: the same spheres, lights and sky, whatever their
/// cameras and image settings. Each view comes as a scene of its own (its camera
/// set), so comparing the `Arc`s would compile every view afresh (1 ms a view for
/// hw3, 0.1 s for 100,000 spheres); comparing the contents takes well under a
/// millisecond.
fn same_contents(a: &Arc<Scene>, b: &Arc<Scene>) -> bool {
    Arc::ptr_eq(a, b) || (a.spheres == b.spheres && a.lights == b.lights && a.sky == b.sky)
}

/// The buffers of the passes, kept from view to view: a fresh full-size buffer for
/// every pass costs its page faults (a 1280×720 frame is 11 MB of `Vec3`), serially,
/// on the critical path of every frame.
#[derive(Default)]
pub struct Buffers {
    /// Sums of samples at full size (see `render::accumulate`: a pass from sample 0
    /// restarts them, so they are never cleared).
    sums: Vec<Vec3>,
    preview_sums: Vec<Vec3>,
    /// What the window was sent, taken back once it has let go.
    frames: Recycler<Frame>,
    rgba: Recycler<Vec<u8>>,
    /// The size of the last view.
    size: (u32, u32),
}

/// Values handed out behind an `Arc`, reused once nobody else holds them.
struct Recycler<T> {
    sent: VecDeque<Arc<T>>,
}

impl<T> Default for Recycler<T> {
    fn default() -> Self {
        Recycler {
            sent: VecDeque::new(),
        }
    }
}

impl<T> Recycler<T> {
    /// The window holds what it shows and the report in flight; a save may hold one.
    const KEPT: usize = 4;

    /// A value sent earlier that nobody holds any more, if any.
    fn take(&mut self) -> Option<T> {
        let free = self.sent.iter().position(|a| Arc::strong_count(a) == 1)?;
        Arc::try_unwrap(self.sent.remove(free)?).ok()
    }

    /// Forgets every value sent: those nobody else holds are freed now, the others
    /// when their holders let go.
    fn forget(&mut self) {
        self.sent.clear();
    }

    /// Calls `fit` on each value nobody else holds.
    fn fit_free(&mut self, mut fit: impl FnMut(&mut T)) {
        for value in &mut self.sent {
            if let Some(value) = Arc::get_mut(value) {
                fit(value);
            }
        }
    }

    /// `value`, taken and not sent, back for a later [`Recycler::take`].
    fn give_back(&mut self, value: T) {
        self.sent.push_back(Arc::new(value));
    }

    /// `value`, shared, remembered for a later [`Recycler::take`].
    fn send(&mut self, value: T) -> Arc<T> {
        let shared = Arc::new(value);
        self.sent.push_back(Arc::clone(&shared));
        if self.sent.len() > Self::KEPT {
            self.sent.pop_front();
        }
        shared
    }
}

impl Buffers {
    /// At the end of a view: no buffer larger than the view needs, so that what the
    /// idle viewer holds depends on the window's size, not on the sizes before it.
    /// (The sums may be the pixels of a frame of an earlier, larger view, handed over
    /// by the last pass: 44 MB after a 2560×1440 view.) Shrinking moves nothing.
    fn fit(&mut self) {
        let n = self.size.0 as usize * self.size.1 as usize;
        fit(&mut self.sums, n);
        // The preview's values are read by the view's first full pass only.
        self.preview_sums = Vec::new();
        self.frames.fit_free(|frame| fit(&mut frame.pixels, n));
        self.rgba.fit_free(|rgba| fit(rgba, 4 * n));
    }
}

/// `buffer` cut to at most `len` values, its spare capacity freed.
fn fit<T>(buffer: &mut Vec<T>, len: usize) {
    buffer.truncate(len);
    buffer.shrink_to_fit();
}

/// Renders all passes of `job`, reporting each; stops early when cancelled.
pub fn run(
    job: &Job,
    cache: &mut TracerCache,
    buffers: &mut Buffers,
    sink: &dyn Fn(Report),
) -> Result<(), RenderError> {
    let scene = job.scene.as_ref();
    let mut opts = scene.settings();
    opts.width = job.width;
    opts.height = job.height;
    opts.check()?;
    // The fast tracer comes from the cache; the f64 reference (a `reference` quality)
    // is built for each view.
    match opts.quality.precision {
        Precision::Fast => {
            let tracer = cache.tracer(&job.scene, &opts)?;
            passes(job, tracer, &opts, buffers, sink)
        }
        Precision::Reference => {
            let reference = render::make_tracer(scene, &opts)?;
            passes(job, reference.as_ref(), &opts, buffers, sink)
        }
    }
}

/// The passes of `job` with `tracer` (generic, so that the fast tracer's samples are
/// direct calls).
fn passes<T: SampleTracer + ?Sized>(
    job: &Job,
    tracer: &T,
    opts: &Settings,
    buffers: &mut Buffers,
    sink: &dyn Fn(Report),
) -> Result<(), RenderError> {
    let control = job.control.as_ref();
    let (w, h) = (job.width, job.height);
    let target = opts.quality.spp;
    let passes = plan(w, h, target, job.preview_factor);
    let last = passes.len() - 1;
    if buffers.size != (w, h) {
        // A new size: the pooled buffers of the old one are let go, also those the
        // window still holds (taken back, a 2560×1440 frame kept its 44 MB in the
        // pool while the window showed a 640×360 view).
        buffers.size = (w, h);
        buffers.frames.forget();
        buffers.rgba.forget();
    }
    resize_buffer(&mut buffers.sums, w as usize * h as usize, Vec3::ZERO);
    // The lattice a preview has traced, until the first full pass takes it.
    let mut previewed = None;
    for (index, pass) in passes.into_iter().enumerate() {
        if control.is_cancelled() {
            return Err(RenderError::Cancelled);
        }
        let start = Instant::now();
        // The last pass of one sample converts its rows for the screen as it traces
        // them (its sums are the frame's values); it takes the screen buffer first, and
        // gives it back if cancelled. Other passes are traced first: a cancelled one
        // returns before the screen buffers are taken.
        let last_single = index == last && pass == Pass::Samples(0..1);
        let mut early_rgba = last_single.then(|| buffers.rgba.take().unwrap_or_default());
        let traced = trace_pass(
            tracer,
            opts,
            buffers,
            &mut previewed,
            pass,
            early_rgba.as_mut(),
            control,
        );
        let (samples, pass_pixels, preview) = match traced {
            Ok(done) => done,
            Err(e) => {
                if let Some(rgba) = early_rgba {
                    buffers.rgba.give_back(rgba);
                }
                return Err(e);
            }
        };
        let mut frame = buffers.frames.take().unwrap_or_else(|| Frame::new(0, 0));
        (frame.width, frame.height) = (w, h);
        let rgba = match early_rgba {
            Some(rgba) => {
                // The sums are the frame's values, mended and on the screen already:
                // handed over, not copied (11 MB at 1280×720), and the frame's old
                // pixels become the next view's sums.
                std::mem::swap(&mut frame.pixels, &mut buffers.sums);
                rgba
            }
            None => {
                let mut rgba = buffers.rgba.take().unwrap_or_default();
                match &preview {
                    Some((width, factor)) => fill_upscaled_for_screen(
                        &mut frame,
                        &mut rgba,
                        (&buffers.preview_sums, *width),
                        *factor,
                        opts.encoding,
                    ),
                    None => {
                        let sums = &buffers.sums;
                        fill_for_screen(&mut frame, &mut rgba, opts.encoding, |j, row| {
                            let from = &sums[j * row.len()..(j + 1) * row.len()];
                            render::pixel_values(from, samples, row);
                        });
                    }
                }
                rgba
            }
        };
        if index == last {
            buffers.fit();
        }
        sink(Report::Frame(Shown {
            generation: job.generation,
            frame: buffers.frames.send(frame),
            rgba: buffers.rgba.send(rgba),
            samples,
            target,
            preview: preview.is_some(),
            pass_pixels,
            done: index == last,
            pass_seconds: start.elapsed().as_secs_f64(),
            since_submit: job.submitted.elapsed().as_secs_f64(),
        }));
    }
    Ok(())
}

/// Traces `pass` into the buffers: `(samples so far, pixel-samples traced, the
/// preview's width and factor)`. With `screen`, a pass of sample 0 also mends each row
/// and writes it there as RGBA bytes.
#[allow(clippy::type_complexity)]
fn trace_pass<T: SampleTracer + ?Sized>(
    tracer: &T,
    opts: &Settings,
    buffers: &mut Buffers,
    previewed: &mut Option<Lattice>,
    pass: Pass,
    screen: Option<&mut Vec<u8>>,
    control: &RenderControl,
) -> Result<(u32, u64, Option<(u32, u32)>), RenderError> {
    let (w, h) = (opts.width, opts.height);
    let screen = screen.map(|rgba| ScreenRows::new(rgba, w, h, opts.encoding));
    let after_row = |j: u32, row: &mut [Vec3]| {
        if let Some(screen) = &screen {
            render::mend_non_finite(row);
            screen.put(j as usize, row);
        }
    };
    Ok(match pass {
        Pass::Preview {
            width,
            height,
            factor,
        } => {
            // One pixel of each block, as the first full pass would trace it: that pass
            // then takes these instead of tracing them again.
            let lattice = Lattice { factor };
            let values = &mut buffers.preview_sums;
            resize_buffer(values, width as usize * height as usize, Vec3::ZERO);
            lattice::sample_lattice(tracer, opts, lattice, values, control)?;
            *previewed = Some(lattice);
            // Shown from the values themselves: a copy resolved into a frame would cost
            // 0.8 ms a preview, most of it the fresh pages of 2.8 MB.
            (
                0,
                u64::from(width) * u64::from(height),
                Some((width, factor)),
            )
        }
        Pass::Samples(range) => {
            let end = range.end;
            let mut pixels = u64::from(w) * u64::from(h) * range.len() as u64;
            let sums = &mut buffers.sums;
            match previewed.take() {
                Some(lattice) if range == (0..1) => {
                    let values = &buffers.preview_sums;
                    pixels -= values.len() as u64;
                    let around = (lattice, values.as_slice());
                    lattice::accumulate_first_around(
                        tracer, opts, around, sums, control, &after_row,
                    )?;
                }
                _ if range == (0..1) => {
                    render::accumulate_first(tracer, opts, sums, control, &after_row)?;
                }
                _ => {
                    render::accumulate(tracer, opts, range, sums, control)?;
                }
            };
            (end, pixels, None)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{hw3_scene, HW3_DEFAULT_SEED};
    use crate::settings::Encoding;
    use crate::viewer::buffer::to_rgba_top_down;
    use std::sync::Mutex;
    use std::time::Duration;

    /// The frames a worker reports, in order; a failed render fails the test.
    #[derive(Default)]
    struct Collected(Mutex<Vec<Shown>>);

    impl Collected {
        fn sink(&self) -> impl Fn(Report) + '_ {
            |r: Report| match r {
                Report::Frame(s) => self.0.lock().unwrap().push(s),
                Report::Failed { message, .. } => panic!("render failed: {message}"),
            }
        }

        fn into_frames(self) -> Vec<Shown> {
            self.0.into_inner().unwrap()
        }
    }

    fn collect(worker_scene: Scene, w: u32, h: u32) -> Vec<Shown> {
        let shown = Collected::default();
        let job = Job::new(7, Arc::new(worker_scene), (w, h), 4);
        run(
            &job,
            &mut TracerCache::default(),
            &mut Buffers::default(),
            &shown.sink(),
        )
        .unwrap();
        shown.into_frames()
    }

    #[test]
    fn the_last_pass_equals_a_one_shot_render() {
        let mut scene = hw3_scene(HW3_DEFAULT_SEED);
        scene.image.spp = Some(5);
        let (w, h) = (192, 108);
        let shown = collect(scene.clone(), w, h);
        // Preview, then samples 1, 2, 4, 5.
        let counts: Vec<u32> = shown.iter().map(|s| s.samples).collect();
        assert_eq!(counts, vec![0, 1, 2, 4, 5]);
        assert!(shown[0].preview && !shown[1].preview);
        assert!(shown.last().unwrap().done && !shown[3].done);
        let mut opts = scene.settings();
        opts.width = w;
        opts.height = h;
        let (expected, _) = render::render(&scene, &opts, &RenderControl::default()).unwrap();
        assert_eq!(*shown.last().unwrap().frame, expected);
        // The 1-sample pass is the first sample of the 5-spp pattern (its lattice
        // taken from the preview).
        let tracer = render::make_tracer(&scene, &opts).unwrap();
        let mut sums = vec![Vec3::ZERO; (w * h) as usize];
        render::accumulate(tracer.as_ref(), &opts, 0..1, &mut sums, &Default::default()).unwrap();
        let first = render::resolve(&sums, 1, w, h);
        assert_eq!(*shown[1].frame, first);
        assert_eq!(
            *shown[1].rgba,
            to_rgba_top_down(&shown[1].frame, Encoding::Linear)
        );
        assert_eq!(*shown[0].frame, expected_preview(&first, 4));
        assert_eq!(
            *shown[0].rgba,
            to_rgba_top_down(&shown[0].frame, Encoding::Linear)
        );
    }

    /// After a large view, a small one leaves no buffer larger than it needs, whether
    /// the window still held the large frame when the small view began (it keeps it
    /// until the small view's first pass shows) or had let go of it.
    #[test]
    fn buffers_shrink_to_the_view_after_a_larger_one() {
        let mut scene = hw3_scene(HW3_DEFAULT_SEED);
        scene.image.spp = Some(1);
        let scene = Arc::new(scene);
        for window_holds_the_large_frame in [true, false] {
            let (mut cache, mut buffers) = (TracerCache::default(), Buffers::default());
            let shown = Collected::default();
            let sink = shown.sink();
            let large = Job::new(1, Arc::clone(&scene), (400, 300), 4);
            run(&large, &mut cache, &mut buffers, &sink).unwrap();
            let held = window_holds_the_large_frame.then(|| shown.0.lock().unwrap().pop());
            shown.0.lock().unwrap().clear();
            let small = Job::new(2, Arc::clone(&scene), (40, 30), 4);
            run(&small, &mut cache, &mut buffers, &sink).unwrap();
            drop(held);
            let n = 40 * 30;
            assert!(buffers.sums.capacity() <= n, "{}", buffers.sums.capacity());
            assert!(buffers.preview_sums.capacity() <= n);
            for frame in &buffers.frames.sent {
                assert!(frame.pixels.capacity() <= n, "{}", frame.pixels.capacity());
            }
            for rgba in &buffers.rgba.sent {
                assert!(rgba.capacity() <= 4 * n, "{}", rgba.capacity());
            }
        }
    }

    /// What a preview at 1/`factor` of the size shows, from the first full pass: over
    /// each block, the pixel in its middle (the block's last one at a short edge).
    fn expected_preview(first: &Frame, factor: u32) -> Frame {
        let (w, h) = (first.width, first.height);
        let middle = |x: u32, n: u32| (x / factor * factor + factor / 2).min(n - 1);
        let mut big = Frame::new(w, h);
        for j in 0..h {
            for i in 0..w {
                big.pixels[(j * w + i) as usize] = first.get(middle(i, w), middle(j, h));
            }
        }
        big
    }

    #[test]
    fn one_sample_views_take_the_preview_pixels_into_the_full_frame() {
        // One sample a pixel (the orbit's case: a row at a time through the tracer),
        // sizes that do not divide by the factor, the fast and the reference tracer.
        for renderer in [Precision::Fast, Precision::Reference] {
            let mut scene = hw3_scene(HW3_DEFAULT_SEED);
            scene.image.spp = Some(1);
            let (w, h) = (190, 107);
            let job = |s: &Scene| Job::new(1, Arc::new(s.clone()), (w, h), 3);
            let mut opts = scene.settings();
            (opts.width, opts.height) = (w, h);
            opts.quality.precision = renderer;
            let shown = Collected::default();
            let tracer = render::make_tracer(&scene, &opts).unwrap();
            passes(
                &job(&scene),
                tracer.as_ref(),
                &opts,
                &mut Buffers::default(),
                &shown.sink(),
            )
            .unwrap();
            let shown = shown.into_frames();
            assert_eq!(shown.len(), 2, "{renderer:?}");
            let (expected, _) = render::render(&scene, &opts, &RenderControl::default()).unwrap();
            assert_eq!(*shown[1].frame, expected, "{renderer:?}");
            assert_eq!(
                *shown[0].frame,
                expected_preview(&expected, 3),
                "{renderer:?}"
            );
            for s in &shown {
                assert_eq!(
                    *s.rgba,
                    to_rgba_top_down(&s.frame, Encoding::Linear),
                    "{renderer:?}"
                );
            }
            // The full pass traced the pixels the preview had not.
            assert_eq!(shown[0].pass_pixels, 64 * 36);
            assert_eq!(shown[1].pass_pixels, u64::from(w * h) - 64 * 36);
        }
    }

    #[test]
    fn reused_buffers_give_the_same_passes_and_spare_what_is_held() {
        // Three samples (passes add to the sums) and one (the last pass hands the
        // sums over as the frame, and gets the frame's old pixels as the next sums).
        for spp in [3, 1] {
            // Every pass of each job, with fresh buffers: what the reused ones must give.
            // 192×108 has a preview; 96×54 has none, and lets the larger buffers go.
            let mut scene = hw3_scene(HW3_DEFAULT_SEED);
            scene.image.spp = Some(spp);
            let jobs = [(192, 108), (192, 108), (96, 54), (192, 108)];
            let fresh: Vec<Vec<Shown>> = jobs
                .iter()
                .map(|&(w, h)| collect(scene.clone(), w, h))
                .collect();
            // The same jobs through one set of buffers; the sink keeps only the first job's
            // passes (as a window still showing them would), drops the others at once.
            let (mut cache, mut buffers) = (TracerCache::default(), Buffers::default());
            let scene = Arc::new(scene);
            let held = Mutex::new(Vec::new());
            let mut addresses: Vec<Vec<*const Vec3>> = Vec::new();
            for (n, &size) in jobs.iter().enumerate() {
                let seen = Mutex::new(Vec::new());
                let sink = |r: Report| match r {
                    Report::Frame(s) => {
                        let copy = (
                            (*s.frame).clone(),
                            (*s.rgba).clone(),
                            s.frame.pixels.as_ptr(),
                        );
                        seen.lock().unwrap().push(copy);
                        if n == 0 {
                            held.lock().unwrap().push(s);
                        }
                    }
                    Report::Failed { message, .. } => panic!("render failed: {message}"),
                };
                let job = Job::new(n as u64, Arc::clone(&scene), size, 4);
                run(&job, &mut cache, &mut buffers, &sink).unwrap();
                let seen = seen.into_inner().unwrap();
                assert_eq!(seen.len(), fresh[n].len(), "spp {spp} job {n}");
                for (k, (frame, rgba, _)) in seen.iter().enumerate() {
                    assert_eq!(*frame, *fresh[n][k].frame, "spp {spp} job {n} pass {k}");
                    assert_eq!(*rgba, *fresh[n][k].rgba, "spp {spp} job {n} pass {k}");
                }
                addresses.push(seen.iter().map(|s| s.2).collect());
                // What the pool keeps that nobody else holds fits this view: the
                // memory of a larger one before it is not kept.
                let pixels = size.0 as usize * size.1 as usize;
                for f in buffers
                    .frames
                    .sent
                    .iter()
                    .filter(|a| Arc::strong_count(a) == 1)
                {
                    assert_eq!(f.pixels.len(), pixels, "spp {spp} job {n}");
                    assert!(f.pixels.capacity() <= 2 * pixels, "spp {spp} job {n}");
                }
                assert!(buffers.sums.capacity() <= 2 * pixels, "spp {spp} job {n}");
            }
            // The passes the "window" kept were not written over by later jobs.
            for (k, s) in held.into_inner().unwrap().iter().enumerate() {
                assert_eq!(*s.frame, *fresh[0][k].frame, "spp {spp} held pass {k}");
                assert_eq!(*s.rgba, *fresh[0][k].rgba, "spp {spp} held pass {k}");
                assert!(!addresses[1..]
                    .iter()
                    .flatten()
                    .any(|&a| a == s.frame.pixels.as_ptr()));
            }
        }
    }

    #[test]
    fn views_of_one_scene_compile_it_once() {
        // Each view comes as a scene of its own with its camera set, as the window
        // submits them: the spheres are compiled once, and each view still equals a
        // render of it; a moved sphere is compiled afresh.
        use crate::viewer::controls::{Action, CameraControl};
        let mut base = hw3_scene(HW3_DEFAULT_SEED);
        base.image.spp = Some(1);
        let (w, h) = (96, 54);
        let (mut cache, mut buffers) = (TracerCache::default(), Buffers::default());
        let mut camera = CameraControl::new(&base);
        let mut view = |scene: &Scene, cache: &mut TracerCache, n: u64| {
            let shown = Collected::default();
            let job = Job::new(n, Arc::new(scene.clone()), (w, h), 4);
            run(&job, cache, &mut buffers, &shown.sink()).unwrap();
            let last = shown.into_frames().pop().unwrap();
            let mut opts = scene.settings();
            (opts.width, opts.height) = (w, h);
            let (expected, _) = render::render(scene, &opts, &RenderControl::default()).unwrap();
            assert_eq!(*last.frame, expected, "view {n}");
        };
        let drag = Action::Drag {
            dx: 40.0,
            dy: 0.0,
            height: h,
        };
        let mut seen = base.clone();
        for n in 0..3 {
            camera.apply(&base, w, h, drag);
            seen.camera = Some(camera.spec(&base, w, h));
            view(&seen, &mut cache, n);
        }
        assert_eq!(cache.compiles, 1);
        seen.spheres[3].center.x += 0.25;
        view(&seen, &mut cache, 3);
        assert_eq!(cache.compiles, 2);
    }

    /// A tracer that cancels its job as soon as it traces.
    struct Cancelling<'a> {
        tracer: &'a FastTracer,
        control: &'a RenderControl,
    }

    impl SampleTracer for Cancelling<'_> {
        fn sample(&self, s: f32, t: f32, counts: &mut crate::trace::RayCounts) -> Vec3 {
            self.control.cancel();
            self.tracer.sample(s, t, counts)
        }
    }

    #[test]
    fn a_pass_cancelled_midway_keeps_the_buffers() {
        // Cancelled inside a preview, and inside a last pass of one sample (which takes
        // the screen buffer before it traces).
        for (spp, factor) in [(2, 4), (1, 1)] {
            let mut scene = hw3_scene(HW3_DEFAULT_SEED);
            scene.image.spp = Some(spp);
            let (mut cache, mut buffers) = (TracerCache::default(), Buffers::default());
            let scene = Arc::new(scene);
            let first = Job::new(1, Arc::clone(&scene), (192, 108), factor);
            run(&first, &mut cache, &mut buffers, &|_| {}).unwrap();
            let pooled = (buffers.frames.sent.len(), buffers.rgba.sent.len());
            assert!(pooled.0 > 0 && pooled.1 > 0);
            // The next view is cancelled inside its first pass.
            let second = Job::new(2, Arc::clone(&scene), (192, 108), factor);
            let mut opts = scene.settings();
            (opts.width, opts.height) = (192, 108);
            let tracer = Cancelling {
                tracer: cache.tracer(&scene, &opts).unwrap(),
                control: &second.control,
            };
            let shown = |_: Report| panic!("a cancelled pass was shown");
            let result = passes(&second, &tracer, &opts, &mut buffers, &shown);
            assert!(matches!(result, Err(RenderError::Cancelled)), "{result:?}");
            let now = (buffers.frames.sent.len(), buffers.rgba.sent.len());
            assert_eq!(now, pooled, "spp {spp}, preview factor {factor}");
            assert!(buffers.frames.take().is_some() && buffers.rgba.take().is_some());
        }
    }

    #[test]
    fn a_new_job_cancels_the_old_one() {
        let (tx, rx) = mpsc::channel();
        let mut worker = Worker::spawn(move |r| {
            let _ = tx.send(r);
        });
        let mut big = hw3_scene(HW3_DEFAULT_SEED);
        big.image.spp = Some(64);
        worker.submit(1, Arc::new(big), (640, 360), 4);
        let mut small = hw3_scene(HW3_DEFAULT_SEED);
        small.image.spp = Some(1);
        worker.submit(2, Arc::new(small), (32, 18), 4);
        // The small job completes; the big one never reaches its last pass.
        loop {
            match rx.recv_timeout(Duration::from_secs(60)).expect("a report") {
                Report::Frame(s) if s.generation == 2 && s.done => {
                    assert_eq!((s.frame.width, s.frame.height), (32, 18));
                    break;
                }
                Report::Frame(s) => assert!(!(s.generation == 1 && s.done)),
                Report::Failed { message, .. } => panic!("{message}"),
            }
        }
        drop(worker);
    }

    #[test]
    fn bad_sizes_are_reported_not_panicked() {
        let (tx, rx) = mpsc::channel();
        let mut worker = Worker::spawn(move |r| {
            let _ = tx.send(r);
        });
        worker.submit(3, Arc::new(hw3_scene(HW3_DEFAULT_SEED)), (0, 10), 4);
        match rx.recv_timeout(Duration::from_secs(60)).expect("a report") {
            Report::Failed { generation, .. } => assert_eq!(generation, 3),
            Report::Frame(_) => panic!("a 0-wide frame rendered"),
        }
    }
}
