//! The image buffer: linear RGB, row 0 at the BOTTOM (as in GLUT).

use glam::Vec3;

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

    /// Pixel `(i, j)`, `j` counted from the bottom.
    pub fn get(&self, i: u32, j: u32) -> Vec3 {
        self.pixels[j as usize * self.width as usize + i as usize]
    }
}
