//! Pixel buffers for the screen. A [`Frame`] has row 0 at the BOTTOM (`j = 0`, as in
//! GLUT); screens have row 0 at the top, so this is where the viewer flips it, once,
//! with the same byte conversion as the files ([`ByteEncoder`], in the settings'
//! encoding) so that a screenshot at 1:1 equals the saved image.

use glam::Vec3;
use rayon::prelude::*;

use crate::image_io::{to_byte, ByteEncoder, Encoding};
use crate::render::Frame;

/// The frame as RGBA bytes in `encoding`, row 0 at the top, alpha 255 (the layout of
/// `pixels`). Rows in parallel: serially the conversion costs a fifth of a
/// full-resolution pass.
pub fn to_rgba_top_down(frame: &Frame, encoding: Encoding) -> Vec<u8> {
    let w = (frame.width as usize).max(1);
    let mut bytes = vec![0u8; frame.pixels.len() * 4];
    let bytes_of = ByteEncoder::new(encoding);
    bytes
        .par_chunks_mut(w * 4)
        .zip(frame.pixels.par_chunks(w).rev())
        .for_each(|(out, row)| rgba_row(row, out, bytes_of));
    bytes
}

/// `buffer` resized to `len` for reuse, and its memory given back when it is far
/// larger than that: after the window has been large, a smaller one does not keep the
/// large one's memory.
pub fn resize_buffer<T: Clone>(buffer: &mut Vec<T>, len: usize, value: T) {
    buffer.resize(len, value);
    if buffer.capacity() > len.saturating_mul(2) {
        buffer.shrink_to_fit();
    }
}

/// The rows of an RGBA buffer (row 0 at the top), for image rows `j` counted from the
/// bottom, each behind its own lock: a pass converts its rows as it traces them, on
/// whichever thread traced them, while they are still in cache (a separate fill after
/// the pass reads the 11 MB frame of 1280×720 again: 1.9 ms on two threads).
pub struct ScreenRows<'a> {
    rows: Vec<std::sync::Mutex<&'a mut [u8]>>,
    bytes_of: ByteEncoder,
}

impl<'a> ScreenRows<'a> {
    /// `rgba` resized for `width`×`height`, to be filled in `encoding`.
    pub fn new(rgba: &'a mut Vec<u8>, width: u32, height: u32, encoding: Encoding) -> Self {
        let w = (width as usize).max(1);
        resize_buffer(rgba, width as usize * height as usize * 4, 0);
        ScreenRows {
            rows: rgba
                .chunks_mut(w * 4)
                .rev()
                .map(std::sync::Mutex::new)
                .collect(),
            bytes_of: ByteEncoder::new(encoding),
        }
    }

    /// Image row `j` (from the bottom) as RGBA bytes, as [`fill_for_screen`] writes it.
    pub fn put(&self, j: usize, pixels: &[Vec3]) {
        let mut row = self.rows[j].lock().unwrap_or_else(|e| e.into_inner());
        rgba_row(pixels, &mut row, self.bytes_of);
    }
}

/// One row of pixels as RGBA bytes. Not inlined: compiled once, the same code for
/// every caller (inlined, its code follows each caller's, and its cost shifts by up to
/// a quarter with unrelated edits). One loop per encoding, each with its conversion
/// inlined.
#[inline(never)]
fn rgba_row(pixels: &[Vec3], out: &mut [u8], bytes_of: ByteEncoder) {
    match bytes_of {
        ByteEncoder::Linear => rgba_words(pixels, out, to_byte),
        ByteEncoder::Srgb(table) => rgba_words(pixels, out, |c| table.byte(c)),
    }
}

#[inline(always)]
fn rgba_words(pixels: &[Vec3], out: &mut [u8], byte: impl Fn(f32) -> u8) {
    let (out, _) = out.as_chunks_mut::<4>();
    for (o, p) in out.iter_mut().zip(pixels) {
        *o = rgba_word(*p, &byte);
    }
}

/// A pixel as RGBA bytes, alpha 255: built as one 32-bit word, so that it is stored
/// once (the compiler then converts four pixels at a time).
#[inline(always)]
fn rgba_word(p: Vec3, byte: impl Fn(f32) -> u8) -> [u8; 4] {
    let [r, g, b] = [p.x, p.y, p.z].map(|c| u32::from(byte(c)));
    (r | g << 8 | b << 16 | 0xff << 24).to_le_bytes()
}

/// Fills every row of `frame` (its size set beforehand) with `row(j, pixels)`, `j`
/// counted from the bottom, and writes the same rows into `rgba` (resized to fit) as
/// RGBA bytes in `encoding`, row 0 at the top, alpha 255 (the layout of `pixels`).
/// Rows run in parallel and each row is converted while it is still in cache; the
/// buffers may be reused ones, as every byte is written.
pub fn fill_for_screen(
    frame: &mut Frame,
    rgba: &mut Vec<u8>,
    encoding: Encoding,
    row: impl Fn(usize, &mut [Vec3]) + Sync,
) {
    let w = (frame.width as usize).max(1);
    let n = frame.width as usize * frame.height as usize;
    resize_buffer(&mut frame.pixels, n, Vec3::ZERO);
    let screen = ScreenRows::new(rgba, frame.width, frame.height, encoding);
    frame
        .pixels
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(j, pixels)| {
            row(j, pixels);
            screen.put(j, pixels);
        });
}

/// [`fill_for_screen`] for a frame that shows `preview` (one-sample values of an
/// image at 1/`factor` of the size, `width` wide, row 0 at the bottom; non-finite ones
/// shown as 0) with each of its pixels as a `factor`×`factor` block, anchored at the
/// bottom-left like the image (a block cut by the top or right edge is cut short; a
/// `preview` too small for the frame goes on with its last column and row).
///
/// A row of blocks at a time: each preview pixel is converted to bytes once, not once
/// a pixel of its block, and the block's first row is copied into the others
/// (converting every pixel of a block, with a division a pixel, costs a sixth of a
/// preview's time).
pub fn fill_upscaled_for_screen(
    frame: &mut Frame,
    rgba: &mut Vec<u8>,
    (preview, width): (&[Vec3], u32),
    factor: u32,
    encoding: Encoding,
) {
    let (w, factor) = (frame.width as usize, factor.max(1) as usize);
    let bytes_of = ByteEncoder::new(encoding);
    let n = w * frame.height as usize;
    resize_buffer(&mut frame.pixels, n, Vec3::ZERO);
    resize_buffer(rgba, n * 4, 0);
    let pw = width as usize;
    let ph = preview.len().checked_div(pw).unwrap_or(0);
    if n == 0 || ph == 0 {
        return;
    }
    frame
        .pixels
        .par_chunks_mut(w * factor)
        // Screen rows run top-down: the bottom row of blocks is at the end.
        .zip(rgba.par_rchunks_mut(w * 4 * factor))
        .enumerate()
        // A row of blocks' values and bytes, in buffers kept by each thread.
        .for_each_init(
            || (vec![Vec3::ZERO; pw], vec![[0u8; 4]; pw]),
            |(source, words), (block_row, (pixels, bytes))| {
                let start = block_row.min(ph - 1) * pw;
                crate::render::pixel_values(&preview[start..start + pw], 1, source);
                rgba_row(source, words.as_flattened_mut(), bytes_of);
                let (first, rest) = pixels.split_at_mut(w);
                let (first_bytes, rest_bytes) = bytes.split_at_mut(w * 4);
                // The source column advances every `factor` pixels and stops at the last.
                let (mut from, mut left) = (0, factor);
                for (p, o) in first.iter_mut().zip(first_bytes.as_chunks_mut::<4>().0) {
                    (*p, *o) = (source[from], words[from]);
                    left -= 1;
                    if left == 0 {
                        (from, left) = ((from + 1).min(pw - 1), factor);
                    }
                }
                for row in rest.chunks_mut(w) {
                    row.copy_from_slice(first);
                }
                for row in rest_bytes.chunks_mut(w * 4) {
                    row.copy_from_slice(first_bytes);
                }
            },
        );
}

/// Where a `w`×`h` image sits, centred, in a `surface_w`×`surface_h` surface: the
/// offset of its top-left corner (negative when the image is larger and is clipped).
pub fn centre_offset(w: u32, h: u32, surface_w: u32, surface_h: u32) -> (i64, i64) {
    (
        (i64::from(surface_w) - i64::from(w)) / 2,
        (i64::from(surface_h) - i64::from(h)) / 2,
    )
}

/// Draws top-down RGBA `rgba` (`w`×`h`) centred into a softbuffer surface of
/// `0x00RRGGBB` words, black around it. Row by row over the visible part only, with
/// no test a pixel: the blit shares the cores with the render.
pub fn blit_xrgb(rgba: &[u8], w: u32, h: u32, dst: &mut [u32], surface_w: u32, surface_h: u32) {
    let (ox, oy) = centre_offset(w, h, surface_w, surface_h);
    // The image's visible columns and rows: those that land inside the surface.
    let visible = |offset: i64, size: u32, surface: u32| {
        let first = (-offset).max(0);
        let end = i64::from(size).min(i64::from(surface) - offset);
        (first as usize, end.max(first) as usize)
    };
    let ((x0, x1), (y0, y1)) = (visible(ox, w, surface_w), visible(oy, h, surface_h));
    // Black only where a border shows: the image covers less than the surface.
    if (x1 - x0, y1 - y0) != (surface_w as usize, surface_h as usize) {
        dst.fill(0);
    }
    let (w, sw) = (w as usize, surface_w as usize);
    let (pixels, _) = rgba.as_chunks::<4>();
    for y in y0..y1 {
        let to = (y as i64 + oy) as usize * sw + (x0 as i64 + ox) as usize;
        let row = &pixels[y * w + x0..y * w + x1];
        for (d, &[r, g, b, _]) in dst[to..to + row.len()].iter_mut().zip(row) {
            *d = u32::from(r) << 16 | u32::from(g) << 8 | u32::from(b);
        }
    }
}

/// The image pixel `(i, j)` (`j` from the BOTTOM) under window position `(x, y)` (from
/// the top-left), for an image of `w`×`h` centred 1:1 in a window of
/// `surface_w`×`surface_h`; `None` outside the image.
pub fn window_to_pixel(
    x: f64,
    y: f64,
    w: u32,
    h: u32,
    surface_w: u32,
    surface_h: u32,
) -> Option<(u32, u32)> {
    let (ox, oy) = centre_offset(w, h, surface_w, surface_h);
    let ix = (x - ox as f64).floor();
    let iy = (y - oy as f64).floor();
    if ix < 0.0 || iy < 0.0 || ix >= f64::from(w) || iy >= f64::from(h) {
        return None;
    }
    Some((ix as u32, h - 1 - iy as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×2 frame whose pixels encode their coordinates.
    fn frame() -> Frame {
        let mut f = Frame::new(3, 2);
        for j in 0..2 {
            for i in 0..3 {
                f.pixels[j * 3 + i] = Vec3::new(i as f32 / 255.0, j as f32 / 255.0, 1.0);
            }
        }
        f
    }

    #[test]
    fn rgba_puts_the_bottom_row_last() {
        let rgba = to_rgba_top_down(&frame(), Encoding::Linear);
        assert_eq!(rgba.len(), 3 * 2 * 4);
        // Top-left of the screen is (i=0, j=1); bottom-right is (i=2, j=0).
        assert_eq!(&rgba[0..4], &[0, 1, 255, 255]);
        assert_eq!(&rgba[20..24], &[2, 0, 255, 255]);
    }

    #[test]
    fn rgba_equals_the_file_bytes() {
        let mut f = frame();
        f.pixels[1] = Vec3::new(-1.0, 0.5, 2.0);
        f.pixels[2] = Vec3::new(0.0031308, 0.2, 0.9);
        for encoding in Encoding::ALL {
            let rgb = crate::image_io::to_rgb8(&f, encoding);
            let rgba = to_rgba_top_down(&f, encoding);
            for (px, chunk) in rgb.pixels().zip(rgba.chunks_exact(4)) {
                assert_eq!(&px.0, &chunk[..3]);
                assert_eq!(chunk[3], 255);
            }
            // The rows a pass converts as it traces them are the same bytes.
            let mut screen = Vec::new();
            let rows = ScreenRows::new(&mut screen, f.width, f.height, encoding);
            for (j, row) in f.pixels.chunks(3).enumerate() {
                rows.put(j, row);
            }
            drop(rows);
            assert_eq!(screen, rgba, "{encoding}");
        }
    }

    #[test]
    fn upscaled_previews_repeat_blocks_from_the_bottom_left() {
        let mut preview = frame();
        // 5×3 from 3×2 at factor 2: the top row and the right column are half blocks.
        let mut big = Frame::new(5, 3);
        let mut rgba = Vec::new();
        let values = (preview.pixels.as_slice(), preview.width);
        fill_upscaled_for_screen(&mut big, &mut rgba, values, 2, Encoding::Linear);
        for (i, j, (pi, pj)) in [
            (0, 0, (0, 0)),
            (1, 1, (0, 0)),
            (2, 1, (1, 0)),
            (4, 2, (2, 1)),
        ] {
            assert_eq!(big.get(i, j), preview.get(pi, pj), "({i}, {j})");
        }
        assert_eq!(rgba, to_rgba_top_down(&big, Encoding::Linear));
        // A preview too small for the frame: its last column and row go on.
        let mut wide = Frame::new(8, 6);
        fill_upscaled_for_screen(&mut wide, &mut rgba, values, 2, Encoding::Linear);
        assert_eq!(wide.get(7, 5), preview.get(2, 1));
        assert_eq!(wide.get(7, 0), preview.get(2, 0));
        assert_eq!(rgba, to_rgba_top_down(&wide, Encoding::Linear));
        // A value that is not finite is shown (and kept for `S`) as 0.
        preview.pixels[4] = Vec3::new(f32::NAN, 0.5, f32::INFINITY);
        let values = (preview.pixels.as_slice(), preview.width);
        fill_upscaled_for_screen(&mut big, &mut rgba, values, 2, Encoding::Linear);
        assert_eq!(big.get(2, 2), Vec3::ZERO);
        assert_eq!(big.get(3, 2), Vec3::ZERO);
        assert_eq!(big.get(0, 2), preview.get(0, 1));
        assert_eq!(rgba, to_rgba_top_down(&big, Encoding::Linear));
    }

    #[test]
    fn xrgb_centres_and_clears() {
        let rgba = to_rgba_top_down(&frame(), Encoding::Linear);
        let mut dst = vec![7u32; 5 * 4];
        blit_xrgb(&rgba, 3, 2, &mut dst, 5, 4);
        // Offset (1, 1): the image's top-left pixel (i=0, j=1) is at surface (1, 1).
        assert_eq!(dst[0], 0);
        assert_eq!(dst[5 + 1], 0x00_00_01_ff);
        assert_eq!(dst[2 * 5 + 3], 0x00_02_00_ff);
        assert_eq!(dst[3 * 5 + 4], 0);
        // A smaller surface clips instead of panicking: offset (0, 0) (−½ rounds to
        // 0), so the image's top-left two pixels.
        let mut small = vec![7u32; 2];
        blit_xrgb(&rgba, 3, 2, &mut small, 2, 1);
        assert_eq!(small, [0x00_00_01_ff, 0x00_01_01_ff]);
        // Wider than the surface but shorter: clipped left and right, black above
        // and below. Offset (−1, 1): surface (0, 1) shows the image's (1, top).
        let mut tall = vec![7u32; 4];
        blit_xrgb(&rgba, 3, 2, &mut tall, 1, 4);
        assert_eq!(tall, [0, 0x00_01_01_ff, 0x00_01_00_ff, 0]);
        // Exactly the surface's size: every word written, none cleared.
        let mut exact = vec![7u32; 3 * 2];
        blit_xrgb(&rgba, 3, 2, &mut exact, 3, 2);
        assert_eq!(exact[0], 0x00_00_01_ff);
        assert_eq!(exact[5], 0x00_02_00_ff);
    }

    #[test]
    fn window_positions_count_rows_from_the_bottom() {
        assert_eq!(
            window_to_pixel(0.0, 0.0, 320, 180, 320, 180),
            Some((0, 179))
        );
        assert_eq!(
            window_to_pixel(319.9, 179.9, 320, 180, 320, 180),
            Some((319, 0))
        );
        assert_eq!(window_to_pixel(320.0, 0.0, 320, 180, 320, 180), None);
        // Centred in a larger window: 40 px of border on each side.
        assert_eq!(
            window_to_pixel(40.0, 10.0, 320, 180, 400, 200),
            Some((0, 179))
        );
        assert_eq!(window_to_pixel(39.0, 10.0, 320, 180, 400, 200), None);
    }
}
