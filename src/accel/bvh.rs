//! A bounding volume hierarchy over sphere bounding boxes: binary, built with the
//! binned surface-area heuristic, flattened depth-first (the left child follows its
//! parent), traversed near child first. It only proposes candidates; the exact
//! sphere tests decide.

use glam::Vec3;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, other: &Aabb) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    fn half_area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    fn centre(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Node {
    pub bounds: Aabb,
    /// Leaf: index of the first item; inner node: index of the right child.
    pub index: u32,
    /// Items in a leaf; 0 for an inner node (its left child is the next node).
    pub count: u32,
    /// Inner node: the split axis, for near-child-first traversal.
    pub axis: u32,
}

pub struct Bvh {
    pub nodes: Vec<Node>,
    /// Item indices in leaf order.
    pub items: Vec<u32>,
}

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// Depth after which splits are by count: keeps any tree below `STACK` levels.
const MAX_SAH_DEPTH: u32 = 48;
const STACK: usize = 96;

impl Bvh {
    /// Builds over `boxes` (one per item).
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let mut items: Vec<u32> = (0..boxes.len() as u32).collect();
        let centres: Vec<Vec3> = boxes.iter().map(Aabb::centre).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len().max(1));
        if !boxes.is_empty() {
            build_node(boxes, &centres, &mut items, 0, 0, &mut nodes);
        }
        Bvh { nodes, items }
    }

    /// Calls `visit(item)` for every item whose box the ray `o + t·d` (`inv_d = 1/d`)
    /// meets within `[0, t_max]`; `visit` returns a lower `t_max` when it finds a hit.
    #[inline]
    pub fn traverse(
        &self,
        o: Vec3,
        inv_d: Vec3,
        mut t_max: f32,
        mut visit: impl FnMut(u32) -> Option<f32>,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let negative = [inv_d.x < 0.0, inv_d.y < 0.0, inv_d.z < 0.0];
        let mut stack = [0u32; STACK];
        let mut top = 0usize;
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            if slab(&n.bounds, o, inv_d, t_max) {
                if n.count > 0 {
                    for &item in &self.items[n.index as usize..(n.index + n.count) as usize] {
                        if let Some(t) = visit(item) {
                            t_max = t_max.min(t);
                        }
                    }
                } else {
                    // Near child first: the left child holds the smaller coordinates.
                    let (near, far) = if negative[n.axis as usize] {
                        (n.index, node + 1)
                    } else {
                        (node + 1, n.index)
                    };
                    stack[top] = far;
                    top += 1;
                    node = near;
                    continue;
                }
            }
            if top == 0 {
                return;
            }
            top -= 1;
            node = stack[top];
        }
    }
}

/// Whether the ray meets the box at some `t` in `[0, t_max]`.
#[inline(always)]
fn slab(b: &Aabb, o: Vec3, inv_d: Vec3, t_max: f32) -> bool {
    let t0 = (b.min - o) * inv_d;
    let t1 = (b.max - o) * inv_d;
    // min/max ignore NaN (0·∞ on a ray in a box face plane), keeping the test
    // conservative.
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

fn build_node(
    boxes: &[Aabb],
    centres: &[Vec3],
    items: &mut [u32],
    first: u32,
    depth: u32,
    nodes: &mut Vec<Node>,
) -> u32 {
    let mut bounds = Aabb::EMPTY;
    let mut centre_bounds = Aabb::EMPTY;
    for &i in items.iter() {
        bounds.grow(&boxes[i as usize]);
        let c = centres[i as usize];
        centre_bounds.grow(&Aabb { min: c, max: c });
    }
    let me = nodes.len() as u32;
    nodes.push(Node {
        bounds,
        index: first,
        count: items.len() as u32,
        axis: 0,
    });
    if items.len() <= MAX_LEAF {
        return me;
    }
    // Deep in the tree, split at the median so that the depth stays within the stack.
    let split = if depth < MAX_SAH_DEPTH {
        best_split(boxes, centres, items, &centre_bounds, &bounds)
    } else {
        let axis = (centre_bounds.max - centre_bounds.min).max_position();
        Some((axis, f32::NAN)) // NaN: nothing goes left, so the count split below applies
    };
    let Some((axis, split)) = split else {
        return me; // no split beats a leaf
    };
    let mid = partition(items, |i| centres[i as usize][axis] < split);
    // Degenerate partitions (all centres equal on the axis) split by count.
    let mid = if mid == 0 || mid == items.len() {
        items.sort_unstable_by(|&a, &b| {
            centres[a as usize][axis].total_cmp(&centres[b as usize][axis])
        });
        items.len() / 2
    } else {
        mid
    };
    let (left, right) = items.split_at_mut(mid);
    let right_index = if items_len_is_large(left.len() + right.len()) {
        // Big subtrees build on two threads, into their own vectors, then splice.
        let (mut l, mut r) = (Vec::new(), Vec::new());
        rayon::join(
            || build_node(boxes, centres, left, first, depth + 1, &mut l),
            || build_node(boxes, centres, right, first + mid as u32, depth + 1, &mut r),
        );
        let base = nodes.len() as u32;
        nodes.extend(l.into_iter().map(|n| offset(n, base)));
        let right_base = nodes.len() as u32;
        nodes.extend(r.into_iter().map(|n| offset(n, right_base)));
        right_base
    } else {
        build_node(boxes, centres, left, first, depth + 1, nodes);
        build_node(boxes, centres, right, first + mid as u32, depth + 1, nodes)
    };
    nodes[me as usize].index = right_index;
    nodes[me as usize].count = 0;
    nodes[me as usize].axis = axis as u32;
    me
}

/// Subtrees this big are worth a thread of their own.
fn items_len_is_large(n: usize) -> bool {
    n >= 8192
}

/// A node of a subtree built at index 0, moved to start at `base`.
fn offset(mut n: Node, base: u32) -> Node {
    if n.count == 0 {
        n.index += base; // inner: right-child index is relative to the subtree
    }
    n
}

/// The binned-SAH split `(axis, position)`, or `None` when a leaf is cheaper.
fn best_split(
    boxes: &[Aabb],
    centres: &[Vec3],
    items: &[u32],
    centre_bounds: &Aabb,
    bounds: &Aabb,
) -> Option<(usize, f32)> {
    let mut best: Option<(f32, usize, f32)> = None;
    for axis in 0..3 {
        let lo = centre_bounds.min[axis];
        let hi = centre_bounds.max[axis];
        if hi <= lo {
            continue;
        }
        let scale = BINS as f32 / (hi - lo);
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        let mut bin_count = [0u32; BINS];
        for &i in items {
            let b = (((centres[i as usize][axis] - lo) * scale) as usize).min(BINS - 1);
            bin_bounds[b].grow(&boxes[i as usize]);
            bin_count[b] += 1;
        }
        // Sweep from the right, then from the left, evaluating the cost of each plane.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0u32; BINS];
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for b in (1..BINS).rev() {
            acc.grow(&bin_bounds[b]);
            n += bin_count[b];
            right_area[b] = acc.half_area();
            right_count[b] = n;
        }
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for b in 0..BINS - 1 {
            acc.grow(&bin_bounds[b]);
            n += bin_count[b];
            if n == 0 || right_count[b + 1] == 0 {
                continue;
            }
            let cost = acc.half_area() * n as f32 + right_area[b + 1] * right_count[b + 1] as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, lo + (b + 1) as f32 / scale));
            }
        }
    }
    let (cost, axis, split) = best?;
    // A leaf costs one test per item; an inner node about one box test plus its children.
    let leaf_cost = bounds.half_area() * items.len() as f32;
    (cost < leaf_cost || items.len() > 16).then_some((axis, split))
}

/// Moves the items for which `left` holds to the front; returns how many there are.
fn partition(items: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut mid = 0;
    for k in 0..items.len() {
        if left(items[k]) {
            items.swap(k, mid);
            mid += 1;
        }
    }
    mid
}
