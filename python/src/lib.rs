//! The Python module `whitted` (SPEC §7): scenes in, numpy arrays out, through the
//! same library calls as the command line, so that the same options give the same
//! bytes. The GIL is released while a render runs; Ctrl-C cancels it.
#![forbid(unsafe_code)]

use std::path::PathBuf;
use std::sync::mpsc::RecvTimeoutError;
use std::time::Duration;

use numpy::{PyArray1, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use whitted::image_io::{self, Format};
use whitted::render::{Frame, RenderControl};
use whitted::settings::{Encoding, Overrides, Precision, Preset, Region, Settings, Tile};

create_exception!(
    whitted,
    SceneError,
    PyValueError,
    "A scene that cannot be loaded; `.path`, `.line` and `.column` say where."
);

/// A scene error as Python's `SceneError`, with its position as attributes.
fn scene_error(py: Python<'_>, e: whitted::SceneError) -> PyErr {
    let err = SceneError::new_err(e.to_string());
    let value = err.value(py);
    let _ = value.setattr("path", e.path.clone());
    let _ = value.setattr("line", e.line);
    let _ = value.setattr("column", e.column);
    let _ = value.setattr("message", e.message.clone());
    err
}

/// A validated scene: spheres, lights, sky, camera and its file's image settings.
/// Pickles as its TOML text, so it travels to other processes.
#[pyclass(module = "whitted", name = "Scene", frozen)]
struct PyScene {
    inner: whitted::Scene,
}

#[pymethods]
impl PyScene {
    /// A short name (the file's stem, or "hw3").
    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }

    /// How many spheres the scene holds.
    #[getter]
    fn spheres(&self) -> usize {
        self.inner.spheres.len()
    }

    /// Frames of the scene's animation (1 for a still scene).
    #[getter]
    fn frames(&self) -> u32 {
        self.inner.frames()
    }

    /// Frames a second of the scene's animation (24 without an `[animation]` table).
    #[getter]
    fn fps(&self) -> f64 {
        self.inner.fps()
    }

    /// How many point lights the scene holds.
    #[getter]
    fn lights(&self) -> usize {
        self.inner.lights.len()
    }

    /// The scene as a scene file (TOML); `parse_scene` of it gives the scene back.
    fn to_toml(&self) -> String {
        whitted::scene::to_toml(&self.inner)
    }

    fn __repr__(&self) -> String {
        format!(
            "<whitted.Scene {:?}: {} spheres, {} lights>",
            self.inner.name,
            self.inner.spheres.len(),
            self.inner.lights.len()
        )
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let rebuild = py.import("whitted._whitted")?.getattr("_scene_from_toml")?;
        let args = (self.to_toml(), self.inner.name.clone());
        (rebuild, args).into_pyobject(py)
    }
}

/// Rebuilds a pickled scene.
#[pyfunction]
fn _scene_from_toml(py: Python<'_>, text: &str, name: String) -> PyResult<PyScene> {
    let mut inner = whitted::Scene::from_toml_str(text, &name).map_err(|e| scene_error(py, e))?;
    inner.name = name;
    Ok(PyScene { inner })
}

/// Reads, parses and validates a scene file.
#[pyfunction]
fn load_scene(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
    let inner = py
        .detach(|| whitted::Scene::load(&path))
        .map_err(|e| scene_error(py, e))?;
    Ok(PyScene { inner })
}

/// Parses and validates scene text; `path` names it in errors.
#[pyfunction]
#[pyo3(signature = (text, path = "<string>"))]
fn parse_scene(py: Python<'_>, text: &str, path: &str) -> PyResult<PyScene> {
    let inner = whitted::Scene::from_toml_str(text, path).map_err(|e| scene_error(py, e))?;
    Ok(PyScene { inner })
}

/// The built-in scene of the assignment, its 48 small balls drawn from `seed`.
#[pyfunction]
#[pyo3(signature = (seed = whitted::scene::HW3_DEFAULT_SEED))]
fn hw3_scene(seed: u64) -> PyScene {
    PyScene {
        inner: whitted::scene::hw3_scene(seed),
    }
}

/// A rectangle `(x, y, width, height)`, origin top-left.
type Rect = (u32, u32, u32, u32);

/// The keyword options of `render`, `render_linear` and `plan`, as the command line's.
#[derive(Default)]
struct Options {
    width: Option<u32>,
    height: Option<u32>,
    spp: Option<u32>,
    depth: Option<u32>,
    seed: Option<u64>,
    quality: Option<String>,
    encoding: Option<String>,
    region: Option<Rect>,
    tile: Option<(u32, u32)>,
    frame: Option<u32>,
    threads: Option<usize>,
    reference: bool,
}

/// The keywords [`Options`] knows.
const KEYWORDS: &str =
    "width, height, spp, depth, seed, quality, encoding, region, tile, frame, threads, reference";

impl Options {
    /// The options of a call's keyword arguments; `None` values count as not given,
    /// an unknown keyword is a `TypeError` as in any Python function.
    fn from_kwargs(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Options> {
        let mut o = Options::default();
        let Some(kwargs) = kwargs else {
            return Ok(o);
        };
        for (key, value) in kwargs.iter() {
            let key: String = key.extract()?;
            if value.is_none() {
                continue;
            }
            match key.as_str() {
                "width" => o.width = Some(value.extract()?),
                "height" => o.height = Some(value.extract()?),
                "spp" => o.spp = Some(value.extract()?),
                "depth" => o.depth = Some(value.extract()?),
                "seed" => o.seed = Some(value.extract()?),
                "quality" => o.quality = Some(value.extract()?),
                "encoding" => o.encoding = Some(value.extract()?),
                "frame" => o.frame = Some(value.extract()?),
                "region" => o.region = Some(value.extract()?),
                "tile" => o.tile = Some(value.extract()?),
                "threads" => o.threads = Some(value.extract()?),
                "reference" => o.reference = value.extract()?,
                other => {
                    return Err(PyTypeError::new_err(format!(
                        "unexpected keyword argument '{other}' (expected {KEYWORDS})"
                    )))
                }
            }
        }
        Ok(o)
    }

    /// What to render: the scene (the frame asked for, as a still scene) and the
    /// settings these options make of the scene's, checked.
    fn resolve(&self, scene: &whitted::Scene) -> PyResult<(whitted::Scene, Settings)> {
        let settings = self.settings(scene)?;
        let Some(k) = self.frame else {
            return Ok((scene.clone(), settings));
        };
        if k >= scene.frames() {
            return Err(PyValueError::new_err(format!(
                "frame {k} does not exist: the scene has {} frames (0 to {})",
                scene.frames(),
                scene.frames() - 1
            )));
        }
        Ok((scene.frame(k, settings.width, settings.height), settings))
    }

    /// The settings these options make of `scene`'s, checked.
    fn settings(&self, scene: &whitted::Scene) -> PyResult<Settings> {
        let quality = match &self.quality {
            None => None,
            Some(name) => Some(
                name.parse::<Preset>()
                    .map_err(|e| PyValueError::new_err(e.to_string()))?,
            ),
        };
        let encoding = match &self.encoding {
            None => None,
            Some(name) => Some(
                name.parse::<Encoding>()
                    .map_err(|e| PyValueError::new_err(e.to_string()))?,
            ),
        };
        let overrides = Overrides {
            encoding,
            quality,
            width: self.width,
            height: self.height,
            spp: self.spp,
            max_depth: self.depth,
            seed: self.seed,
            precision: self.reference.then_some(Precision::Reference),
            region: self.region.map(|(x, y, width, height)| Region {
                x,
                y,
                width,
                height,
            }),
            tile: self.tile.map(|(index, count)| Tile { index, count }),
            threads: self.threads,
        };
        let settings = scene.settings().with(&overrides);
        settings
            .check()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(settings)
    }
}

/// Renders with the GIL released, waking every 20 ms to look for Ctrl-C: a signal
/// cancels the render (within a row of pixels) and raises `KeyboardInterrupt`. The
/// render's end wakes the wait at once.
fn render_frame(py: Python<'_>, scene: &whitted::Scene, settings: &Settings) -> PyResult<Frame> {
    let control = RenderControl::default();
    let outcome = py.detach(|| {
        std::thread::scope(|s| {
            let (done, finished) = std::sync::mpsc::channel();
            let control = &control;
            let job = s.spawn(move || {
                let result = whitted::render(scene, settings, control);
                let _ = done.send(());
                result
            });
            loop {
                match finished.recv_timeout(Duration::from_millis(20)) {
                    Ok(()) | Err(RecvTimeoutError::Disconnected) => return Ok(job.join()),
                    Err(RecvTimeoutError::Timeout) => {}
                }
                // Python's signal handler only sets a flag; it is read with the GIL.
                if let Err(interrupt) = Python::attach(|py| py.check_signals()) {
                    control.cancel();
                    let _ = job.join();
                    return Err(interrupt);
                }
            }
        })
    })?;
    match outcome {
        Ok(Ok((frame, _stats))) => Ok(frame),
        Ok(Err(e)) => Err(PyValueError::new_err(e.to_string())),
        Err(_) => Err(PyRuntimeError::new_err("the render panicked")),
    }
}

/// Renders `scene` to 8-bit RGB: a numpy array `(height, width, 3)` of `uint8`, top
/// row first, the bytes `whitted render -o x.png` writes with the same options.
/// Keywords: width, height, spp, depth, seed, quality, region=(x, y, w, h),
/// tile=(i, n), threads, reference.
#[pyfunction]
#[pyo3(signature = (scene, **options))]
fn render<'py>(
    py: Python<'py>,
    scene: &PyScene,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let (scene, settings) = Options::from_kwargs(options)?.resolve(&scene.inner)?;
    let frame = render_frame(py, &scene, &settings)?;
    let (w, h) = (frame.width as usize, frame.height as usize);
    let bytes = image_io::to_rgb8(&frame, settings.encoding).into_raw();
    PyArray1::from_vec(py, bytes).reshape([h, w, 3])
}

/// Renders `scene` to linear RGB: a numpy array `(height, width, 3)` of `float32`, top
/// row first, the values `whitted render -o x.exr` writes with the same options.
/// Keywords as `render`'s.
#[pyfunction]
#[pyo3(signature = (scene, **options))]
fn render_linear<'py>(
    py: Python<'py>,
    scene: &PyScene,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let (scene, settings) = Options::from_kwargs(options)?.resolve(&scene.inner)?;
    let frame = render_frame(py, &scene, &settings)?;
    let (w, h) = (frame.width as usize, frame.height as usize);
    let values = image_io::to_rgb32f(&frame).into_raw();
    PyArray1::from_vec(py, values).reshape([h, w, 3])
}

/// The size `(width, height)` and the rectangle `(x, y, w, h)` of what `render` with
/// these options gives: the whole image's size and the part rendered. Checks the
/// options as `render` does (`ValueError`), without rendering. Keywords as `render`'s.
#[pyfunction]
#[pyo3(signature = (scene, **options))]
fn plan(scene: &PyScene, options: Option<&Bound<'_, PyDict>>) -> PyResult<((u32, u32), Rect)> {
    let (_, settings) = Options::from_kwargs(options)?.resolve(&scene.inner)?;
    let a = settings.area();
    Ok((
        (settings.width, settings.height),
        (a.x, a.y, a.width, a.height),
    ))
}

/// Writes an image file atomically, format by extension, as the command line does:
/// a `uint8` array `(h, w, 3)` to `.png .ppm .bmp .jpg`; a `float32` array (linear
/// values) to any of those or `.exr`, its bytes made in `encoding` ("linear" or
/// "srgb"). `ppm_binary` writes P6 instead of P3.
#[pyfunction]
#[pyo3(signature = (path, image, *, ppm_binary=false, encoding="linear"))]
fn write_image(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    ppm_binary: bool,
    encoding: &str,
) -> PyResult<()> {
    let encoding: Encoding = encoding
        .parse()
        .map_err(|e: whitted::settings::UnknownEncoding| PyValueError::new_err(e.to_string()))?;
    let format =
        Format::from_path(&path, ppm_binary).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let shape_error = || PyValueError::new_err("expected an array of shape (height, width, 3)");
    let io = |e: image_io::SaveError| PyErr::new::<pyo3::exceptions::PyOSError, _>(e.to_string());
    if let Ok(bytes) = image.extract::<PyReadonlyArray3<u8>>() {
        let shape = bytes.shape();
        if shape[2] != 3 {
            return Err(shape_error());
        }
        let (h, w) = (shape[0] as u32, shape[1] as u32);
        let raw = bytes
            .as_slice()
            .map(<[u8]>::to_vec)
            .unwrap_or_else(|_| bytes.as_array().iter().copied().collect());
        let rgb = image::RgbImage::from_raw(w, h, raw).ok_or_else(shape_error)?;
        if format == Format::Exr {
            return Err(PyValueError::new_err(
                "EXR holds linear values: pass a float32 array",
            ));
        }
        return py
            .detach(|| image_io::save_rgb8(&rgb, &path, format))
            .map_err(io);
    }
    let values: PyReadonlyArray3<f32> = image.extract().map_err(|_| {
        PyValueError::new_err("expected a uint8 or float32 array of shape (height, width, 3)")
    })?;
    let shape = values.shape();
    if shape[2] != 3 {
        return Err(shape_error());
    }
    let (h, w) = (shape[0] as u32, shape[1] as u32);
    let raw = values
        .as_slice()
        .map(<[f32]>::to_vec)
        .unwrap_or_else(|_| values.as_array().iter().copied().collect());
    let top_down = image::Rgb32FImage::from_raw(w, h, raw).ok_or_else(shape_error)?;
    let frame = image_io::parts::frame_of(&top_down);
    py.detach(|| image_io::save(&frame, &path, format, encoding))
        .map_err(io)
}

/// The rectangle `(x, y, w, h)` of tile `index` of `count` tiles over a
/// `width`×`height` image, as `--tile index/count` renders it.
#[pyfunction]
fn tile_region(index: u32, count: u32, width: u32, height: u32) -> PyResult<Rect> {
    let r = Tile { index, count }.region(width, height).ok_or_else(|| {
        PyValueError::new_err(format!(
            "tile {index}/{count} does not exist in a {width}x{height} image"
        ))
    })?;
    Ok((r.x, r.y, r.width, r.height))
}

/// The rendering core of `whitted`.
#[pymodule]
fn _whitted(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(parse_scene, m)?)?;
    m.add_function(wrap_pyfunction!(hw3_scene, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(render_linear, m)?)?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    m.add_function(wrap_pyfunction!(tile_region, m)?)?;
    m.add_function(wrap_pyfunction!(_scene_from_toml, m)?)?;
    Ok(())
}
