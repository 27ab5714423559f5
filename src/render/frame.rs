//! The image buffer: linear RGB, row 0 at the BOTTOM (as in GLUT).

use glam::Vec3;
use rayon::prelude::*;

/// Rows converted by one task of [`Frame::bytes_top_first`] at least.
const ROWS_PER_TASK: usize = 32;

/// Linear RGB pixels, row 0 at the BOTTOM.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width × height` pixels, row by row from the bottom.
    pub pixels: Vec<Vec3>,
}

impl Frame {
    /// A black frame.
    pub fn new(width: u32, height: u32) -> Self {
        Frame {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }

    /// 8-bit RGB, TOP row first (the order of files and screens), each value turned
    /// into its byte by `byte` (an encoding's conversion).
    pub fn bytes_top_first(&self, byte: impl Fn(f32) -> u8 + Sync) -> Vec<u8> {
        let w = self.width.max(1) as usize;
        let mut bytes = vec![0u8; self.pixels.len() * 3];
        // Rows in parallel: a 1280x720 frame's bytes take a few milliseconds on one core.
        bytes
            .par_chunks_mut(w * 3)
            .zip(self.pixels.par_chunks_exact(w).rev())
            .with_min_len(ROWS_PER_TASK)
            .for_each(|(out, row)| bytes_of_row(row, out, &byte));
        bytes
    }

    /// Pixel `(i, j)`, `j` counted from the bottom.
    pub fn get(&self, i: u32, j: u32) -> Vec3 {
        self.pixels[j as usize * self.width as usize + i as usize]
    }
}

/// The bytes of a row of pixels into `out` (3 a pixel), by `byte`.
#[inline]
pub(crate) fn bytes_of_row(row: &[Vec3], out: &mut [u8], byte: &impl Fn(f32) -> u8) {
    for (o, p) in out.chunks_exact_mut(3).zip(row) {
        o.copy_from_slice(&[byte(p.x), byte(p.y), byte(p.z)]);
    }
}
