//! The viewer's preview as part of the full frame: the preview traces one pixel of
//! every `factor`×`factor` block of the image — the pixel the full frame's first
//! sample would trace there, at the same film position — and the full frame's first
//! pass then traces only the other pixels and takes these as they are. The preview's
//! work is not thrown away, and the frame is the same to the bit (every sample of a
//! pixel depends only on the pixel: `SampleTracer::sample_row` gives each pixel of any
//! row of positions what `sample` gives it).

use glam::Vec3;

use crate::render::{self, RenderControl, RenderError};
use crate::settings::Settings;
use crate::trace::{RayCounts, SampleTracer};

/// One pixel of every `factor`×`factor` block of the render area, the blocks anchored
/// at the area's bottom-left (as the viewer scales a preview up): the pixel nearest the
/// block's centre that lies in the area.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lattice {
    pub factor: u32,
}

impl Lattice {
    /// Blocks across and up an area of `width`×`height` (a preview's size).
    pub fn blocks(&self, width: u32, height: u32) -> (u32, u32) {
        (width.div_ceil(self.factor), height.div_ceil(self.factor))
    }

    /// The pixel of block `b` along an axis of `n` pixels: its middle one, or the last
    /// pixel of a block cut short by the edge.
    pub fn pick(&self, b: u32, n: u32) -> u32 {
        (b * self.factor + self.factor / 2).min(n - 1)
    }

    /// Whether pixel `x` (of `n` along the axis) is its block's pick.
    pub fn holds(&self, x: u32, n: u32) -> bool {
        x == self.pick(x / self.factor, n)
    }
}

/// The first sample of each lattice pixel of the area of `opts`, into `out` (one value
/// per block, row 0 at the bottom), exactly as [`render::accumulate`] of sample 0
/// computes it for that pixel.
pub fn sample_lattice<T: SampleTracer + ?Sized>(
    tracer: &T,
    opts: &Settings,
    lattice: Lattice,
    out: &mut [Vec3],
    control: &RenderControl,
) -> Result<RayCounts, RenderError> {
    let area = opts.area();
    let (bw, bh) = lattice.blocks(area.width, area.height);
    assert_eq!(out.len(), bw as usize * bh as usize, "one value per block");
    let columns: Vec<u32> = (0..bw)
        .map(|b| area.x + lattice.pick(b, area.width))
        .collect();
    let centres = render::film::centres_of(opts, &columns);
    // The area's bottom row, counted from the image's bottom.
    let j0 = opts.height - (area.y + area.height);
    let progress = u64::from(bw);
    render::bands::for_each_band(
        opts,
        out,
        bw as usize,
        progress,
        control,
        |b, row, counts| {
            let j = j0 + lattice.pick(b as u32, area.height);
            render::progressive::first_samples(tracer, opts, &columns, &centres, j, row, counts);
        },
    )
}

/// [`render::accumulate_first`] (`sums` area-sized, row 0 at the bottom) when `values`
/// (from [`sample_lattice`] of the same tracer and options) already holds the
/// lattice's: the other pixels are traced, the lattice's copied; then `after_row`.
pub fn accumulate_first_around<T: SampleTracer + ?Sized>(
    tracer: &T,
    opts: &Settings,
    (lattice, values): (Lattice, &[Vec3]),
    sums: &mut [Vec3],
    control: &RenderControl,
    after_row: &(dyn Fn(u32, &mut [Vec3]) + Sync),
) -> Result<RayCounts, RenderError> {
    let area = opts.area();
    let (bw, bh) = lattice.blocks(area.width, area.height);
    assert_eq!(
        values.len(),
        bw as usize * bh as usize,
        "one value per block"
    );
    let all: Vec<u32> = (area.x..area.x + area.width).collect();
    let all_centres = render::film::centres_of(opts, &all);
    // The columns of a lattice row that are traced, and the lattice's (with its block).
    let (rest, picked): (Vec<u32>, Vec<u32>) = all
        .iter()
        .partition(|&&i| !lattice.holds(i - area.x, area.width));
    let rest_centres = render::film::centres_of(opts, &rest);
    // Where each goes in the row, and from which block (no division a pixel).
    let rest_at: Vec<usize> = rest.iter().map(|&i| (i - area.x) as usize).collect();
    let picked_at: Vec<(usize, usize)> = picked
        .iter()
        .map(|&i| {
            let a = i - area.x;
            (a as usize, (a / lattice.factor) as usize)
        })
        .collect();
    let j0 = opts.height - (area.y + area.height);
    render::bands::for_each_row(opts, area, sums, 1, 1, control, |j, row, counts| {
        let r = j - j0;
        if !lattice.holds(r, area.height) {
            render::progressive::first_samples(tracer, opts, &all, &all_centres, j, row, counts);
            after_row(j, row);
            return;
        }
        // Traced into the front of the row, then moved to their places from the last
        // one down (each place lies at or after its value's, so nothing unread is
        // overwritten): no buffer a row.
        render::progressive::first_samples(
            tracer,
            opts,
            &rest,
            &rest_centres,
            j,
            &mut row[..rest.len()],
            counts,
        );
        for (k, &a) in rest_at.iter().enumerate().rev() {
            row[a] = row[k];
        }
        let block_row = &values[(r / lattice.factor * bw) as usize..][..bw as usize];
        for &(a, b) in &picked_at {
            row[a] = block_row[b];
        }
        after_row(j, row);
    })
}

#[cfg(test)]
mod tests {
    use super::Lattice;

    #[test]
    fn every_block_has_exactly_one_pixel_of_the_lattice_inside_it() {
        for factor in 1..=7 {
            let lattice = Lattice { factor };
            for n in 1..=40 {
                let (blocks, _) = lattice.blocks(n, 1);
                for b in 0..blocks {
                    let block = b * factor..((b + 1) * factor).min(n);
                    let held: Vec<u32> = block.clone().filter(|&x| lattice.holds(x, n)).collect();
                    assert_eq!(held, vec![lattice.pick(b, n)], "factor {factor}, n {n}");
                    assert!(block.contains(&lattice.pick(b, n)));
                }
            }
        }
    }
}
