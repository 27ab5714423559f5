//! The hierarchy of a large scene, built from its items' Morton order (a linear BVH,
//! Lauterbach et al. 2009): the centres quantized on a cubic grid, 2^10 steps over
//! their largest extent, their coordinates' bits interleaved into one code, the items sorted by it (a radix
//! sort), and every node's items split where their codes' highest differing bit
//! changes. Each split is a binary search in the sorted codes, where the binned
//! surface-area heuristic reads every item of every level twice.

use std::ops::Range;

use arrayvec::ArrayVec;
use glam::{Vec3, Vec3A};
use rayon::prelude::*;

use super::{wide_node_of, Aabb, Bvh, WideNode, MAX_LEAF, WIDTH};

/// Bits of a code an axis: three of them fill 30 bits of a `u32`.
const BITS: u32 = 10;

/// [`Bvh::build`] from the Morton order.
pub(super) fn build<R: Send>(
    len: usize,
    record: impl Fn(usize) -> R + Sync,
    bounds: impl Fn(&R) -> Aabb + Sync,
) -> (Bvh, Vec<R>) {
    // Each item's box centre and largest side, worked out once for the three passes
    // below: a box's widening and outward rounding cost more than reading these
    // 16 bytes back.
    let shapes: Vec<(Vec3, f32)> = (0..len)
        .into_par_iter()
        .map(|k| {
            let b = bounds(&record(k));
            (b.centre().into(), (b.max - b.min).max_element())
        })
        .collect();
    let centre = |k: usize| Vec3A::from(shapes[k].0);
    // Items larger than an eighth of the centres' spread (a ground sphere whose centre
    // lies far below the others) are ordered apart from the rest, on a grid over all
    // the centres, behind them: among the others, their boxes would widen every node
    // above them, and their centres would spread the others' grid, leaving the rest
    // few steps. Bit 30 of their codes is set, so the root's first split divides the
    // two sets.
    let all = centres_box(len, |k| Some(centre(k)));
    let largest = (all.max - all.min).max_element() / 8.0;
    let is_small = |k: usize| shapes[k].1 <= largest;
    let small = centres_box(len, |k| is_small(k).then(|| centre(k)));
    let (on_small, on_all) = (Grid::over(&small), Grid::over(&all));
    let mut keyed: Vec<(u32, u32)> = (0..len)
        .into_par_iter()
        .map(|k| {
            let code = if is_small(k) {
                on_small.code(centre(k))
            } else {
                1 << (3 * BITS) | on_all.code(centre(k))
            };
            (code, k as u32)
        })
        .collect();
    drop(shapes);
    radsort::sort_by_key(&mut keyed, |&(code, _)| code);
    // The records in that order, gathered in one tight loop whose loads overlap; the
    // leaves' boxes are then read from them in order.
    let records: Vec<R> = keyed.par_iter().map(|&(_, k)| record(k as usize)).collect();
    let tree = SortedItems {
        keyed: &keyed,
        records: &records,
        bounds: &bounds,
    };
    // Room for a node every `WIDTH − 1` items, so that the vector is not copied as it
    // grows: the codes' splits leave many leaves of one item (a million spheres make
    // 127,443 nodes, 32 MB). The room not used is never touched.
    let mut nodes = Vec::with_capacity(len / (WIDTH - 1) + 1);
    if len > 0 {
        if len <= MAX_LEAF {
            // A single leaf: a node of one child.
            let b = tree.leaf_bounds(0..len);
            nodes.push(wide_node_of([(b, 0, len as u32)].into_iter()));
        } else {
            tree.node(0..len, &mut nodes);
        }
    }
    (Bvh { nodes }, records)
}

/// The steps of a code's grid over a box of centres.
struct Grid {
    min: Vec3A,
    scale: Vec3A,
}

impl Grid {
    const STEPS: f32 = ((1 << BITS) - 1) as f32;

    fn over(centres: &Aabb) -> Grid {
        let extent = (centres.max - centres.min).max_element();
        // One step length for all three axes: a grid stretched to the centres' extent on each
        // would split a thin layer of balls into thinner ones early, each box as wide
        // as the layer (3.8 times the work of the binned SAH's tree for a ray through
        // a random layer 100 wide and 1 thick, against 1.06 with cubes).
        let scale = if extent > 0.0 {
            Vec3A::splat(Grid::STEPS / extent)
        } else {
            Vec3A::ZERO
        };
        Grid {
            min: centres.min,
            scale,
        }
    }

    /// The Morton code of centre `c`: its steps on the three axes, their bits
    /// interleaved (x's highest).
    fn code(&self, c: Vec3A) -> u32 {
        let q = ((c - self.min) * self.scale).clamp(Vec3A::ZERO, Vec3A::splat(Grid::STEPS));
        spread(q.x as u32) << 2 | spread(q.y as u32) << 1 | spread(q.z as u32)
    }
}

/// The box of the centres `centre(k)` gives, of items `0..len`.
fn centres_box(len: usize, centre: impl Fn(usize) -> Option<Vec3A> + Sync) -> Aabb {
    (0..len)
        .into_par_iter()
        .fold(
            || Aabb::EMPTY,
            |mut b, k| {
                if let Some(c) = centre(k) {
                    b.min = b.min.min(c);
                    b.max = b.max.max(c);
                }
                b
            },
        )
        .reduce(
            || Aabb::EMPTY,
            |mut a, b| {
                a.grow(&b);
                a
            },
        )
}

/// Spreads the low 10 bits of `x` to every third bit.
fn spread(x: u32) -> u32 {
    let mut x = x & 0x3ff;
    x = (x | x << 16) & 0x0300_00ff;
    x = (x | x << 8) & 0x0300_f00f;
    x = (x | x << 4) & 0x030c_30c3;
    x = (x | x << 2) & 0x0924_9249;
    x
}

/// The items sorted by their codes, as the nodes are made from them.
struct SortedItems<'a, R, B> {
    /// Each item's code and index, sorted.
    keyed: &'a [(u32, u32)],
    /// The items' records, in the codes' order.
    records: &'a [R],
    bounds: &'a B,
}

impl<R, B: Fn(&R) -> Aabb> SortedItems<'_, R, B> {
    /// Splits the slots `range` (more than one) where the highest bit in which their
    /// codes differ turns from 0 to 1; items of one code split in the middle.
    fn split(&self, range: Range<usize>) -> [Range<usize>; 2] {
        let keyed = &self.keyed[range.clone()];
        let (first, last) = (keyed[0].0, keyed[keyed.len() - 1].0);
        let mid = if first == last {
            keyed.len() / 2
        } else {
            let bit = 31 - (first ^ last).leading_zeros();
            keyed.partition_point(|&(c, _)| c >> bit & 1 == 0)
        };
        [range.start..range.start + mid, range.start + mid..range.end]
    }

    /// The box of the items in `slots`.
    fn leaf_bounds(&self, slots: Range<usize>) -> Aabb {
        let mut b = Aabb::EMPTY;
        for item in &self.records[slots] {
            b.grow(&(self.bounds)(item));
        }
        b
    }

    /// Makes the node over `range` (more than a leaf's items) and those below it,
    /// depth first; returns its index and box.
    fn node(&self, range: Range<usize>, out: &mut Vec<WideNode>) -> (u32, Aabb) {
        // Open the child of the most items until there are `WIDTH` children.
        let mut children: ArrayVec<Range<usize>, WIDTH> = ArrayVec::new();
        children.extend(self.split(range));
        while children.len() < WIDTH {
            let open = children
                .iter()
                .enumerate()
                .filter(|(_, c)| c.len() > MAX_LEAF)
                .max_by_key(|(_, c)| c.len())
                .map(|(i, _)| i);
            let Some(i) = open else { break };
            let c = children.remove(i);
            let [a, b] = self.split(c);
            children.insert(i, b);
            children.insert(i, a);
        }
        let me = out.len();
        out.push(wide_node_of(std::iter::empty()));
        let mut lanes: ArrayVec<(Aabb, u32, u32), WIDTH> = ArrayVec::new();
        for c in children {
            if c.len() <= MAX_LEAF {
                lanes.push((self.leaf_bounds(c.clone()), c.start as u32, c.len() as u32));
            } else {
                let (index, b) = self.node(c, out);
                lanes.push((b, index, 0));
            }
        }
        let mut b = Aabb::EMPTY;
        lanes.iter().for_each(|(lane, _, _)| b.grow(lane));
        out[me] = wide_node_of(lanes.into_iter());
        (me as u32, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A step on x is the code's bit 2, on y bit 1, on z bit 0; the far corner of the
    /// grid has every bit of 30; the corners' steps round down.
    #[test]
    fn a_code_interleaves_the_steps_x_first() {
        let grid = Grid::over(&Aabb {
            min: Vec3A::ZERO,
            max: Vec3A::splat(Grid::STEPS * 2.0),
        });
        assert_eq!(grid.code(Vec3A::new(2.0, 0.0, 0.0)), 0b100);
        assert_eq!(grid.code(Vec3A::new(0.0, 2.0, 0.0)), 0b010);
        assert_eq!(grid.code(Vec3A::new(0.0, 0.0, 3.9)), 0b001);
        assert_eq!(grid.code(Vec3A::new(4.0, 2.0, 6.0)), 0b101_011);
        assert_eq!(grid.code(Vec3A::splat(Grid::STEPS * 2.0)), (1 << 30) - 1);
        // Outside the box, the nearest step.
        assert_eq!(grid.code(Vec3A::splat(-5.0)), 0);
    }

    /// Bit i of a step goes to bit 3i, for its 10 low bits.
    #[test]
    fn spread_puts_a_coordinate_s_bits_three_apart() {
        assert_eq!(spread(0), 0);
        assert_eq!(spread(0b1011), 0b1_000_001_001);
        assert_eq!(spread(0x3ff), 0x0924_9249);
        assert_eq!(spread(0x7ff), 0x0924_9249, "above 10 bits, dropped");
    }
}
