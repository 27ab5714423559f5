//! Upper bounds on what a scene or a render may ask for, checked before anything is
//! allocated: a scene file, a command line or a Python call beyond them gets a clear
//! error instead of an allocation failure or hours of work.

/// Pixels in one image (2^28: a 16384×16384 image).
pub const MAX_PIXELS: u64 = 1 << 28;
/// Width or height alone.
pub const MAX_SIDE: u32 = 1 << 16;
/// Samples per pixel.
pub const MAX_SPP: u32 = 1 << 16;
/// Maximum ray depth.
pub const MAX_DEPTH: u32 = 64;
/// Spheres in a scene (about 100 MB of them); counted in the file before parsing.
pub const MAX_SPHERES: usize = 1 << 20;
/// Point lights in a scene.
pub const MAX_LIGHTS: usize = 1 << 10;
/// Scene files larger than this are refused before they are read: room for
/// [`MAX_SPHERES`] `[[sphere]]` tables of up to 256 bytes each (a million-sphere file
/// of `make_hw3.py` takes 135 MB).
pub const MAX_FILE_BYTES: u64 = 1 << 28;
/// Scene text parsed as one TOML document at most (the `toml` tree takes 35-65 times
/// the text); larger files must end in a run of `[[sphere]]` tables, which is parsed a
/// batch of tables at a time.
pub const MAX_WHOLE_PARSE_BYTES: u64 = 1 << 24;
/// Bytes of pixels one byte of a PNG or EXR file can hold at most: deflate's largest
/// expansion (1032:1), which no other compression that `png` and `exr` read exceeds.
/// A header that states more pixels than its file can hold is refused before they are
/// allocated.
pub const MAX_EXPANSION: u64 = 1032;
/// Frames of an animation.
pub const MAX_FRAMES: u32 = 1 << 20;
