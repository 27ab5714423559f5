//! The `S` key: the image on screen as PNG and plain PPM in the current folder, under
//! the next free numbered names (`hw3-001.png`, `hw3-001.ppm`, ...), never overwriting.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use crate::image_io::{self, Encoding, Format};
use crate::render::Frame;

/// The scene name made safe for a file name: anything but letters, digits, `-`, `_`
/// and `.` becomes `_`.
pub fn file_stem(scene_name: &str) -> String {
    let stem: String = scene_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = stem.trim_start_matches('.');
    if stem.is_empty() {
        "whitted".into()
    } else {
        stem.into()
    }
}

/// The PNG and PPM names with number `n`.
pub fn names(stem: &str, n: u32) -> (String, String) {
    (format!("{stem}-{n:03}.png"), format!("{stem}-{n:03}.ppm"))
}

/// Hands out numbered names: the first number from 1 whose PNG and PPM are both
/// free, skipping numbers this process has handed out already (their files may still
/// be being written).
#[derive(Debug, Default)]
pub struct Numbering {
    used: HashSet<u32>,
}

impl Numbering {
    /// The next pair of names in `dir`; `exists` says whether a file is there.
    pub fn next(
        &mut self,
        dir: &Path,
        stem: &str,
        exists: impl Fn(&Path) -> bool,
    ) -> (PathBuf, PathBuf) {
        let mut n = 1;
        loop {
            let (png, ppm) = names(stem, n);
            let (png, ppm) = (dir.join(png), dir.join(ppm));
            if !self.used.contains(&n) && !exists(&png) && !exists(&ppm) {
                self.used.insert(n);
                return (png, ppm);
            }
            n += 1;
        }
    }
}

/// Writes the frame to both files (each atomically), its bytes in `encoding` (those
/// on screen).
pub fn save_pair(frame: &Frame, png: &Path, ppm: &Path, encoding: Encoding) -> Result<(), String> {
    let plain = Format::Ppm { binary: false };
    image_io::save(frame, png, Format::Png, encoding).map_err(|e| e.to_string())?;
    image_io::save(frame, ppm, plain, encoding).map_err(|e| e.to_string())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn stems_are_safe_file_names() {
        assert_eq!(file_stem("hw3"), "hw3");
        assert_eq!(file_stem("my scene/β"), "my_scene__");
        assert_eq!(file_stem(".."), "whitted");
        assert_eq!(file_stem(""), "whitted");
    }

    #[test]
    fn numbers_skip_existing_files_and_names_handed_out() {
        let existing: HashSet<PathBuf> = ["hw3-001.png", "hw3-002.ppm", "other-003.png"]
            .iter()
            .map(PathBuf::from)
            .collect();
        let exists = |p: &Path| existing.contains(p);
        let mut numbering = Numbering::default();
        let (png, ppm) = numbering.next(Path::new(""), "hw3", exists);
        assert_eq!(png, PathBuf::from("hw3-003.png"));
        assert_eq!(ppm, PathBuf::from("hw3-003.ppm"));
        let (png, _) = numbering.next(Path::new(""), "hw3", exists);
        assert_eq!(png, PathBuf::from("hw3-004.png"));
        assert_eq!(names("x", 1234).0, "x-1234.png");
    }

    #[test]
    fn saving_twice_writes_new_files_that_decode_to_the_frame() {
        let dir = tempfile::tempdir().unwrap();
        let mut frame = Frame::new(4, 3);
        frame.pixels[0] = Vec3::new(1.0, 0.5, 0.0); // bottom-left
        let mut numbering = Numbering::default();
        let mut written = Vec::new();
        for _ in 0..2 {
            let (png, ppm) = numbering.next(dir.path(), "t", |p| p.exists());
            save_pair(&frame, &png, &ppm, Encoding::Linear).unwrap();
            written.push((png, ppm));
        }
        assert_ne!(written[0].0, written[1].0);
        for (png, ppm) in &written {
            for path in [png, ppm] {
                let img = image::open(path).unwrap().to_rgb8();
                assert_eq!(img.dimensions(), (4, 3));
                assert_eq!(img.get_pixel(0, 2).0, [255, 128, 0]);
                assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0]);
            }
        }
        // A fresh numbering (a new run) does not overwrite them either.
        let (png, _) = Numbering::default().next(dir.path(), "t", |p| p.exists());
        assert!(png.ends_with("t-003.png"));
    }
}
