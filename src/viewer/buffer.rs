//! Pixel buffers for the screen. A [`Frame`] has row 0 at the BOTTOM (`j = 0`, as in
//! GLUT); screens have row 0 at the top, so this is where the viewer flips it, once,
//! with the same byte conversion as the files ([`to_byte`]) so that a screenshot at
//! 1:1 equals the saved image.

use glam::Vec3;
use rayon::prelude::*;

use crate::image_io::to_byte;
use crate::render::Frame;

use super::schedule::preview_source;

/// The frame as RGBA bytes, row 0 at the top, alpha 255 (the layout of `pixels`).
/// Rows in parallel: serially this took a fifth of a full-resolution pass.
pub fn to_rgba_top_down(frame: &Frame) -> Vec<u8> {
    let w = (frame.width as usize).max(1);
    let mut bytes = vec![0u8; frame.pixels.len() * 4];
    bytes
        .par_chunks_mut(w * 4)
        .zip(frame.pixels.par_chunks(w).rev())
        .for_each(|(out, row)| rgba_row(row, out));
    bytes
}

/// One row of pixels as RGBA bytes. Not inlined: compiled once, the same code for
/// every caller (inlined, its cost moved by a quarter with unrelated changes).
#[inline(never)]
fn rgba_row(pixels: &[Vec3], out: &mut [u8]) {
    for (o, p) in out.chunks_exact_mut(4).zip(pixels) {
        // One 32-bit store a pixel.
        let [r, g, b] = [p.x, p.y, p.z].map(|c| u32::from(to_byte(c)));
        let word = r | g << 8 | b << 16 | 0xff << 24;
        o.copy_from_slice(&word.to_le_bytes());
    }
}

/// Fills every row of `frame` (its size set beforehand) with `row(j, pixels)`, `j`
/// counted from the bottom, and writes the same rows into `rgba` (resized to fit) as
/// RGBA bytes, row 0 at the top, alpha 255 (the layout of `pixels`). Rows run in
/// parallel and each row is converted while it is still in cache; the buffers may be
/// reused ones, as every byte is written.
pub fn fill_for_screen(
    frame: &mut Frame,
    rgba: &mut Vec<u8>,
    row: impl Fn(usize, &mut [Vec3]) + Sync,
) {
    let w = (frame.width as usize).max(1);
    let n = frame.width as usize * frame.height as usize;
    frame.pixels.resize(n, Vec3::ZERO);
    rgba.resize(n * 4, 0);
    frame
        .pixels
        .par_chunks_mut(w)
        .zip(rgba.par_chunks_mut(w * 4).rev())
        .enumerate()
        .for_each(|(j, (pixels, out))| {
            row(j, pixels);
            rgba_row(pixels, out);
        });
}

/// Row `j` (from the bottom) of `frame` when it shows `preview` (rendered at
/// 1/`factor` of the size) with each of its pixels as a `factor`×`factor` block,
/// anchored at the bottom-left like the image.
pub fn upscaled_row(preview: &Frame, factor: u32, j: usize, row: &mut [Vec3]) {
    // The source column advances every `factor` pixels: a division a pixel (as in
    // `preview_source`) cost a third of the conversion for the screen.
    let (_, pj) = preview_source(0, j as u32, factor);
    let (pw, pj) = (preview.width as usize, pj.min(preview.height - 1) as usize);
    let source = &preview.pixels[pj * pw..(pj + 1) * pw];
    let (mut pi, mut left) = (0, factor);
    for p in row.iter_mut() {
        *p = source[pi.min(pw - 1)];
        left -= 1;
        if left == 0 {
            (pi, left) = (pi + 1, factor);
        }
    }
}

/// A `width`×`height` frame showing `preview` scaled up (see [`upscaled_row`]).
pub fn upscale(preview: &Frame, factor: u32, width: u32, height: u32) -> Frame {
    let mut frame = Frame::new(width, height);
    frame
        .pixels
        .par_chunks_mut(width.max(1) as usize)
        .enumerate()
        .for_each(|(j, row)| upscaled_row(preview, factor, j, row));
    frame
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
/// `0x00RRGGBB` words, black around it.
pub fn blit_xrgb(rgba: &[u8], w: u32, h: u32, dst: &mut [u32], surface_w: u32, surface_h: u32) {
    dst.fill(0);
    let (ox, oy) = centre_offset(w, h, surface_w, surface_h);
    for y in 0..i64::from(h) {
        let sy = y + oy;
        if sy < 0 || sy >= i64::from(surface_h) {
            continue;
        }
        for x in 0..i64::from(w) {
            let sx = x + ox;
            if sx < 0 || sx >= i64::from(surface_w) {
                continue;
            }
            let s = ((y * i64::from(w) + x) * 4) as usize;
            let (r, g, b) = (rgba[s] as u32, rgba[s + 1] as u32, rgba[s + 2] as u32);
            dst[(sy * i64::from(surface_w) + sx) as usize] = (r << 16) | (g << 8) | b;
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
        let rgba = to_rgba_top_down(&frame());
        assert_eq!(rgba.len(), 3 * 2 * 4);
        // Top-left of the screen is (i=0, j=1); bottom-right is (i=2, j=0).
        assert_eq!(&rgba[0..4], &[0, 1, 255, 255]);
        assert_eq!(&rgba[20..24], &[2, 0, 255, 255]);
    }

    #[test]
    fn rgba_equals_the_file_bytes() {
        let mut f = frame();
        f.pixels[1] = Vec3::new(-1.0, 0.5, 2.0);
        let rgb = crate::image_io::to_rgb8(&f);
        let rgba = to_rgba_top_down(&f);
        for (px, chunk) in rgb.pixels().zip(rgba.chunks_exact(4)) {
            assert_eq!(&px.0, &chunk[..3]);
            assert_eq!(chunk[3], 255);
        }
    }

    #[test]
    fn upscale_repeats_blocks_from_the_bottom_left() {
        let preview = frame();
        let big = upscale(&preview, 2, 5, 3);
        assert_eq!(big.get(0, 0), preview.get(0, 0));
        assert_eq!(big.get(1, 1), preview.get(0, 0));
        assert_eq!(big.get(2, 1), preview.get(1, 0));
        assert_eq!(big.get(4, 2), preview.get(2, 1));
    }

    #[test]
    fn xrgb_centres_and_clears() {
        let rgba = to_rgba_top_down(&frame());
        let mut dst = vec![7u32; 5 * 4];
        blit_xrgb(&rgba, 3, 2, &mut dst, 5, 4);
        // Offset (1, 1): the image's top-left pixel (i=0, j=1) is at surface (1, 1).
        assert_eq!(dst[0], 0);
        assert_eq!(dst[5 + 1], 0x00_00_01_ff);
        assert_eq!(dst[2 * 5 + 3], 0x00_02_00_ff);
        assert_eq!(dst[3 * 5 + 4], 0);
        // A smaller surface clips instead of panicking.
        let mut small = vec![0u32; 2];
        blit_xrgb(&rgba, 3, 2, &mut small, 2, 1);
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
