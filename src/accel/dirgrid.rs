//! A directional grid around one point: a cube map whose cells list the spheres seen
//! in that cell's directions, nearest first. Rays through the point — primary rays
//! from the camera, shadow rays to a point light — test only their cell's spheres:
//! the "light buffer" of Haines and Greenberg (1986), used for the eye as well.
//!
//! Cells are filled conservatively (a sphere's bounding box, widened), so a query
//! sees every sphere it could hit: the grid changes the work, never the answer.

use std::cell::OnceCell;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::round_down;
use super::view::ViewPyramid;

pub(super) struct DirGrid<T = ()> {
    /// The point every ray of the grid passes through.
    pub(super) centre: DVec3,
    /// Cells per face side.
    n: u32,
    /// `n/2`.
    half_n: f32,
    /// Cell `c` lists `items[offsets[c]..offsets[c+1]]`.
    offsets: Vec<u32>,
    /// The cells' entries, cell after cell.
    items: Vec<Listed<T>>,
    /// Spheres that contain the centre: seen in every direction.
    pub(super) always: Vec<u32>,
    /// Spheres seen over a large part of the directions, kept out of the cells when
    /// the grid is built with them apart ([`WIDE_SIN`]), nearest first: every ray of
    /// the grid tests them.
    pub(super) wide: Vec<Listed<T>>,
}

/// A sphere in a cell's list: its index, its nearest distance from the centre rounded
/// down, and what the grid's queries read of it first (`T`), kept in the entry so that
/// a query reads its cell's list in order instead of one sphere's record elsewhere
/// for each entry.
#[derive(Clone, Copy)]
pub(super) struct Listed<T> {
    pub(super) k: u32,
    pub(super) near: f32,
    pub(super) data: T,
}

/// Spheres a unit of parallel work of the build: enough to outweigh its overhead.
const SPHERES_PER_RUN: usize = 2048;

/// Spheres a bucket of the sort by distance on average: few enough for the caches.
const SPHERES_PER_BUCKET: usize = 4096;

/// A grid built with wide spheres apart lists a sphere seen at an angular radius
/// whose sine is at least this (30°, a fifteenth of all directions) in its `wide`
/// list instead of its cells. The ground of the peers' scenes, seen from their light
/// over 28% of the directions, filled 143,885 of a 256-cell grid's cells: four fifths
/// of its entries at 10,000 balls, 28% at 100,000; and most shadow rays, from points on
/// or above it, pass its cells and test it all the same.
const WIDE_SIN: f64 = 0.5;

/// Whether a sphere of radius `r`, its centre `dist` from the grid's point, is seen
/// wide ([`WIDE_SIN`]).
#[inline]
fn seen_wide(r: f64, dist: f64) -> bool {
    r >= WIDE_SIN * dist
}

/// The most spheres a grid keeps apart; with more (a crowd close around the point,
/// which every ray would then test) all stay in the cells.
const MOST_WIDE: usize = 8;

/// The most entries a grid holds, its cells' offsets counted among them
/// ([`cell_places`]): [`ENTRIES_ANY`] and this many a sphere. A sphere a few of its
/// radii from the centre is seen in a large part of the cells, so a crowd of them
/// would list millions of entries each (20,000 balls of radius 1 around a light at
/// 2.5: 330 million, 10 GB); past the bound the build takes a coarser grid, and past
/// the coarsest it may ([`coarser`]) none (see [`DirGrid::build_with`]). Scenes of
/// small spheres stay far below it (a million of them list 3.9 million entries around
/// a light).
const ENTRIES_PER_SPHERE: usize = 8;
/// See [`ENTRIES_PER_SPHERE`].
const ENTRIES_ANY: usize = 1 << 22;

/// The bound of [`ENTRIES_PER_SPHERE`] for `spheres` spheres.
pub(super) fn most_entries(spheres: usize) -> usize {
    ENTRIES_ANY + ENTRIES_PER_SPHERE * spheres
}

/// The bound of each of `grids` grids around points that share one grid's bound
/// ([`most_entries`]) for `spheres` spheres: the lights' grids, which serve equal
/// numbers of rays (a diffuse hit casts a shadow ray to every light). Many lights
/// then get coarser grids, or none, and their memory stays within one grid's
/// whatever their number.
pub(super) fn most_entries_each(spheres: usize, grids: usize) -> usize {
    most_entries(spheres) / grids.max(1)
}

/// The cells of a grid of `n` cells a face side.
fn cell_count(n: u32) -> usize {
    6 * (n as usize) * (n as usize)
}

/// The room a grid of `n` cells a side and entries of `entry_bytes` takes besides
/// its entries, in entries: its cells' offsets (4 bytes each, and one past the last).
fn cell_places(n: u32, entry_bytes: usize) -> usize {
    (cell_count(n) + 1) * size_of::<u32>() / entry_bytes
}

/// The coarsest grid a crowded scene falls back to, in cells a face side: coarser
/// cells would each list most of the crowd, and the point's rays walk the hierarchy
/// instead.
const COARSEST: u32 = 32;

/// The resolutions a crowded grid of `n` cells a side for `spheres` spheres falls
/// back to, finest first: halves of `n`, down to [`COARSEST`] and to no fewer cells
/// than spheres. (A crowd of large spheres fills fewer entries in coarser cells; small
/// spheres fill a few at any resolution, and lists of more than one sphere a cell are
/// slower to walk than the hierarchy.)
fn coarser(n: u32, spheres: usize) -> impl Iterator<Item = u32> {
    std::iter::successors(Some(n / 2), |m| Some(m / 2))
        .take_while(move |&m| m >= COARSEST && cell_count(m) >= spheres)
}

/// At most as many entries as a grid of `n` cells a side around `centre` lists for
/// `spheres` (those `view` may see): a sphere that does not hold the centre is seen in
/// one cell at least, and in as many as its solid angle ω fills of the largest cell's,
/// (2/n)² steradians at most (a face's middle cell, seen square on); with
/// `wide_apart`, a sphere seen wide may be listed apart, in none.
fn fewest_entries(
    centre: DVec3,
    spheres: &[(DVec3, f64)],
    n: u32,
    view: Option<&ViewPyramid>,
    wide_apart: bool,
) -> f64 {
    let largest_cell = (2.0 / f64::from(n)).powi(2);
    spheres
        .par_iter()
        .filter(|&&(c, r)| view.is_none_or(|view| view.may_see(c - centre, r)))
        .map(|&(c, r)| {
            let dist = (c - centre).length();
            if dist <= r || (wide_apart && seen_wide(r, dist)) {
                return 0.0;
            }
            // ω = 2π(1 − cos θ), sin θ = r/dist; rounding errs far below the 1%.
            let cos = (1.0 - (r / dist).powi(2)).sqrt();
            let solid_angle = std::f64::consts::TAU * (1.0 - cos);
            (0.99 * solid_angle / largest_cell).max(1.0)
        })
        .sum()
}

/// Entries a run of the build lists between two looks at the shared count of them.
const PAIRS_PER_COUNT: usize = 1024;

/// What a run of spheres adds to a grid.
#[derive(Default)]
struct Run {
    /// Spheres that contain the centre.
    always: Vec<u32>,
    /// (cell, the sphere's place in the sorted order) for every cell a sphere is seen in.
    pairs: Vec<(u32, u32)>,
    /// The places of the spheres kept apart from the cells.
    wide: Vec<u32>,
}

impl Run {
    /// Room for `spheres` spheres of many cells each, so that the pairs are not copied
    /// as they grow: the room a run does not use is never touched, and untouched
    /// memory costs no page fault.
    fn with_room_for(spheres: usize) -> Run {
        Run {
            always: Vec::new(),
            pairs: Vec::with_capacity(16 * spheres),
            wide: Vec::new(),
        }
    }
}

/// The cells around `centre` in which sphere `k` (`c`, `r`) is seen, into `out` as pairs
/// (cell, `place`); with `wide_apart`, a sphere seen wide ([`WIDE_SIN`]) into `out.wide`
/// instead.
#[allow(clippy::too_many_arguments)]
fn cells_of(
    centre: DVec3,
    c: DVec3,
    r: f64,
    n: u32,
    cones: &CellCones,
    k: u32,
    place: u32,
    wide_apart: bool,
    out: &mut Run,
) {
    let rel = c - centre;
    let reach = r * (1.0 + 1e-6) + 1e-9 * rel.abs().max_element();
    let dist = rel.length();
    if dist <= reach {
        out.always.push(k);
        return;
    }
    if wide_apart && seen_wide(r, dist) {
        out.wide.push(place);
        return;
    }
    let sphere_cone = SphereCone::new(rel, dist, r);
    let (lo, hi) = (rel - DVec3::splat(reach), rel + DVec3::splat(reach));
    let single = only_face(lo, hi);
    let faces = match single {
        Some(face) => face..face + 1,
        None => 0..6,
    };
    for face in faces {
        // In the one face it is seen in, a sphere well in front of the face's plane
        // is seen within its silhouette's rectangle, which lies inside its box's: the
        // box's bounds exceed the tangents' by a relative `reach/a` or more (at least
        // 10⁻⁹), far above their rounding.
        let rect = single
            .and_then(|face| silhouette_rect(face, rel, reach, n))
            .or_else(|| face_rect(face, lo, hi, n));
        let Some([u0, u1, v0, v1]) = rect else {
            continue;
        };
        for v in v0..=v1 {
            for u in u0..=u1 {
                if cones.meets(face, u, v, &sphere_cone) {
                    out.pairs.push((cell_index(face, u, v, n) as u32, place));
                }
            }
        }
    }
}

/// A range of a grid's cells with their ends (`offsets`, the first cell's at
/// `first_cell`) and their entries (`items`, the first at `first_item`), which one
/// thread fills.
struct CellRange<'a, T> {
    first_cell: u32,
    offsets: &'a mut [u32],
    first_item: u32,
    items: &'a mut [Listed<T>],
}

/// `offsets` (each cell's end, the cells' entries counted) and `items` cut into `parts`
/// ranges of cells of about as many entries each: their fills are independent.
fn cell_ranges<'a, T>(
    offsets: &'a mut [u32],
    items: &'a mut [Listed<T>],
    parts: usize,
) -> Vec<CellRange<'a, T>> {
    let total = items.len() as u64;
    let mut ranges = Vec::with_capacity(parts);
    let (mut offsets, mut items) = (offsets, items);
    let (mut first_cell, mut first_item) = (0u32, 0u32);
    for p in 1..=parts as u64 {
        // The cells up to the first whose end reaches the part's share of the entries.
        let share = (total * p / parts as u64) as u32;
        let cells = if p == parts as u64 {
            offsets.len()
        } else {
            offsets.partition_point(|&end| end < share)
        };
        let (these, rest) = offsets.split_at_mut(cells);
        let entries = these.last().map_or(first_item, |&end| end) - first_item;
        let (those, others) = items.split_at_mut(entries as usize);
        ranges.push(CellRange {
            first_cell,
            offsets: these,
            first_item,
            items: those,
        });
        first_cell += cells as u32;
        first_item += entries;
        (offsets, items) = (rest, others);
    }
    ranges
}

/// Widening of each sphere's range in face coordinates (cells are `2/n` wide): covers
/// the rounding of query directions many times over.
const WIDEN: f64 = 1e-4;

/// Counts of ranges laid end to end, each turned into its range's end; returns the
/// last end, the total (a counting sort's first step: each item then goes just
/// before its range's end, taken last to first, which keeps their order).
fn running_ends<N: Copy + Default + std::ops::AddAssign>(counts: &mut [N]) -> N {
    let mut end = N::default();
    for count in counts {
        end += *count;
        *count = end;
    }
    end
}

/// The spheres of a grid around `centre` (those `view` may see), nearest first, each
/// with its entry: its index, its nearest distance from the centre rounded down (so
/// that the early exit of queries stays conservative) and `data` of it. Visited in
/// this order, the stable fill of the cells leaves every cell's list sorted, so
/// closest-hit queries can stop early.
fn nearest_first<T: Copy + Send + Sync>(
    centre: DVec3,
    spheres: &[(DVec3, f64)],
    view: Option<&ViewPyramid>,
    data: impl Fn(DVec3, f64) -> T + Sync,
) -> Vec<((DVec3, f64), Listed<T>)> {
    let entries: Vec<(u32, f32)> = spheres
        .par_iter()
        .with_min_len(SPHERES_PER_RUN)
        .enumerate()
        .filter(|&(_, &(c, r))| view.is_none_or(|view| view.may_see(c - centre, r)))
        .map(|(k, &(c, r))| {
            let dist = (c - centre).length();
            let d = (dist - r) - 1e-6 * (dist + r + centre.abs().max_element());
            (k as u32, round_down(d))
        })
        .collect();
    let Some(&(first, near_first)) = entries.first() else {
        return Vec::new();
    };
    let listed = |k: u32, near: f32| {
        let (c, r) = spheres[k as usize];
        let data = data(c, r);
        ((c, r), Listed { k, near, data })
    };
    // The spheres go into buckets of ranges of the distance, read in index order and
    // written each into its bucket's next place (a pass over memory in order, where a
    // gather in sorted order missed the caches on every sphere); then each bucket, a
    // few thousand spheres that the caches hold, is sorted on its own (a radix sort:
    // in `total_cmp`'s order, stable, so ties stay in index order, and no coin toss
    // per comparison). A bucket's number never decreases with the distance, so the
    // buckets in order are sorted.
    let (lo, hi) = entries.iter().fold(
        (f32::INFINITY, f32::NEG_INFINITY),
        |(lo, hi), &(_, near)| (lo.min(near), hi.max(near)),
    );
    let buckets = entries.len().div_ceil(SPHERES_PER_BUCKET);
    let scale = buckets as f32 / (hi - lo);
    let bucket = |near: f32| {
        if scale.is_finite() {
            (((near - lo) * scale) as usize).min(buckets - 1)
        } else {
            0
        }
    };
    let mut ends = vec![0usize; buckets];
    for &(_, near) in &entries {
        ends[bucket(near)] += 1;
    }
    running_ends(&mut ends);
    // Filled with any entry on the pool's threads first: their page faults overlap.
    let any = listed(first, near_first);
    let mut sorted: Vec<_> = (0..entries.len()).into_par_iter().map(|_| any).collect();
    // Last to first, each before its bucket's end, which leaves `ends` at the starts.
    for &(k, near) in entries.iter().rev() {
        let place = &mut ends[bucket(near)];
        *place -= 1;
        sorted[*place] = listed(k, near);
    }
    let mut rest = sorted.as_mut_slice();
    let mut parts = Vec::with_capacity(buckets);
    for pair in ends.windows(2) {
        let (part, others) = rest.split_at_mut(pair[1] - pair[0]);
        parts.push(part);
        rest = others;
    }
    parts.push(rest);
    parts
        .into_par_iter()
        .for_each(|part| radsort::sort_by_key(part, |(_, entry)| entry.near));
    sorted
}

impl DirGrid {
    /// Builds the grid around `centre` for spheres `(centre, radius)`, with nothing but
    /// their indices and distances in its lists, within [`most_entries`] (see
    /// [`DirGrid::build_with`]).
    pub(super) fn build(
        centre: DVec3,
        spheres: &[(DVec3, f64)],
        n: u32,
        view: Option<&ViewPyramid>,
    ) -> Option<DirGrid> {
        let bound = most_entries(spheres.len());
        DirGrid::build_with(centre, spheres, n, view, |_, _| (), bound, false)
    }
}

impl<T: Copy + Send + Sync> DirGrid<T> {
    /// Cells a face side.
    #[cfg(test)]
    pub(super) fn resolution(&self) -> u32 {
        self.n
    }

    /// The room the grid takes in the unit of its bound: entries and cell offsets
    /// (see [`cell_places`]).
    #[cfg(test)]
    pub(super) fn places(&self) -> usize {
        self.items.len() + cell_places(self.n, size_of::<Listed<T>>())
    }

    /// Every sphere the grid lists, in any cell or in `always`, in index order.
    #[cfg(test)]
    pub(super) fn spheres_listed(&self) -> Vec<u32> {
        let mut listed: Vec<u32> = self.items.iter().map(|e| e.k).collect();
        listed.extend(&self.always);
        listed.extend(self.wide.iter().map(|e| e.k));
        listed.sort_unstable();
        listed.dedup();
        listed
    }

    /// Builds the grid around `centre` for spheres `(centre, radius)`, each entry
    /// carrying `data(centre, radius)` of its sphere; with `view`, for rays through it
    /// only: the spheres wholly outside it are left out; with `wide_apart`, the spheres
    /// seen wide ([`WIDE_SIN`]) are listed apart from the cells, up to [`MOST_WIDE`] of
    /// them. Its cells and entries together stay within `bound` (see [`cell_places`]);
    /// `None` when even the coarsest grid would pass it.
    pub(super) fn build_with(
        centre: DVec3,
        spheres: &[(DVec3, f64)],
        n: u32,
        view: Option<&ViewPyramid>,
        data: impl Fn(DVec3, f64) -> T + Sync,
        bound: usize,
        wide_apart: bool,
    ) -> Option<DirGrid<T>> {
        let room = |m: u32| bound.checked_sub(cell_places(m, size_of::<Listed<T>>()));
        // Sorted once for every resolution tried, and not at all when none has room.
        let sorted = OnceCell::new();
        let sorted = || sorted.get_or_init(|| nearest_first(centre, spheres, view, &data));
        let within = |m: u32, r: usize| DirGrid::build_within(centre, sorted(), m, r, wide_apart);
        let first = room(n).and_then(|r| within(n, r));
        if first.is_some() {
            return first;
        }
        // Crowded: a sphere seen over many cells fills a quarter of them at half the
        // resolution, which has a quarter of the cells. The coarser grids, finest
        // first, skipping those that could not fit by their cells or their spheres'
        // solid angles alone.
        coarser(n, spheres.len())
            .filter_map(|m| Some((m, room(m)?)))
            .filter(|&(m, r)| fewest_entries(centre, spheres, m, view, wide_apart) <= r as f64)
            .find_map(|(m, r)| within(m, r))
    }

    /// The grid of `n` cells a side over the spheres `sorted` ([`nearest_first`]), with
    /// at most `bound` entries, and the spheres seen wide apart if `wide_apart` and
    /// there are at most [`MOST_WIDE`].
    fn build_within(
        centre: DVec3,
        sorted: &[((DVec3, f64), Listed<T>)],
        n: u32,
        bound: usize,
        wide_apart: bool,
    ) -> Option<DirGrid<T>> {
        let faces = cell_count(n);
        let cones = CellCones::shared(n);
        // Each sphere's cells, in runs of spheres on rayon's threads; the runs come
        // back in order, so the pairs stay nearest first. A pair names the sphere by
        // its place in `sorted`. The runs add up their entries as they go, and all stop
        // once the sum passes the bound, or the spheres kept apart pass their most.
        let listed = AtomicUsize::new(0);
        let wide = AtomicUsize::new(0);
        let runs: Vec<Run> = sorted
            .par_chunks(SPHERES_PER_RUN)
            .enumerate()
            .map(|(i, run)| {
                let mut out = Run::with_room_for(run.len());
                let mut counted = 0;
                for (j, &((c, r), Listed { k, .. })) in run.iter().enumerate() {
                    let place = (i * SPHERES_PER_RUN + j) as u32;
                    let was_wide = out.wide.len();
                    cells_of(centre, c, r, n, &cones, k, place, wide_apart, &mut out);
                    if out.wide.len() > was_wide
                        && wide.fetch_add(1, Ordering::Relaxed) >= MOST_WIDE
                    {
                        break;
                    }
                    if out.pairs.len() - counted >= PAIRS_PER_COUNT || j + 1 == run.len() {
                        let new = out.pairs.len() - counted;
                        counted = out.pairs.len();
                        if listed.fetch_add(new, Ordering::Relaxed) + new > bound {
                            break;
                        }
                    }
                }
                out
            })
            .collect();
        if listed.into_inner() > bound {
            return None;
        }
        if wide.into_inner() > MOST_WIDE {
            return DirGrid::build_within(centre, sorted, n, bound, false);
        }
        // Counting sort by cell, stable (it keeps the nearest-first order): `offsets[c]`
        // counts up to the end of cell c, then each entry, taken last to first, goes
        // just before its cell's end, which leaves `offsets[c]` at the cell's start. (A
        // copy of the ends to fill forwards would be fresh memory: a page fault every
        // 1,024 cells.)
        //
        // The offsets are written before the count reads them: a fresh page read first
        // maps the shared zero page, and its first write then faults again and flushes
        // the other threads' address translations (an interrupt to each: the count of
        // a light's grid at 100,000 spheres took 8 ms, written first 1.5 ms). The zero
        // is hidden so that the write stays a write, not an allocation of zeroed memory
        // (LLVM may fold an allocation and a fill of zeros into one).
        let mut offsets = Vec::with_capacity(faces + 1);
        offsets.resize(faces + 1, std::hint::black_box(0u32));
        for &(cell, _) in runs.iter().flat_map(|run| &run.pairs) {
            offsets[cell as usize] += 1;
        }
        let end = running_ends(&mut offsets);
        // Filled with any entry first (every place is written below), on the pool's
        // threads: the fill is the first touch of fresh pages, whose faults then
        // overlap.
        let mut items: Vec<Listed<T>> = match sorted.first() {
            Some(&(_, first)) => (0..end).into_par_iter().map(|_| first).collect(),
            None => Vec::new(),
        };
        let pairs = || runs.iter().rev().flat_map(|run| run.pairs.iter().rev());
        let parts = cell_ranges(&mut offsets, &mut items, rayon::current_num_threads());
        parts.into_par_iter().for_each(|part| {
            for &(cell, place) in pairs() {
                let Some(start) = part
                    .offsets
                    .get_mut(cell.wrapping_sub(part.first_cell) as usize)
                else {
                    continue;
                };
                *start -= 1;
                part.items[(*start - part.first_item) as usize] = sorted[place as usize].1;
            }
        });
        let wide = runs
            .iter()
            .flat_map(|run| &run.wide)
            .map(|&place| sorted[place as usize].1)
            .collect();
        let always = runs.into_iter().flat_map(|run| run.always).collect();
        Some(DirGrid {
            centre,
            n,
            half_n: 0.5 * n as f32,
            offsets,
            items,
            always,
            wide,
        })
    }

    /// The cell of direction `d` (any length, not zero).
    #[inline]
    pub(super) fn cell(&self, d: Vec3) -> usize {
        self.cell_at(self.place(d))
    }

    /// The cell at `place`.
    #[inline]
    pub(super) fn cell_at(&self, place: CellPlace) -> usize {
        cell_index(place.face, place.u, place.v, self.n)
    }

    /// Where direction `d` (any length, not zero) falls: its face, and its cell's
    /// column and row on that face.
    #[inline]
    pub(super) fn place(&self, d: Vec3) -> CellPlace {
        let a = d.abs();
        let (face, major, u, v) = if a.x >= a.y && a.x >= a.z {
            (u32::from(d.x < 0.0), a.x, d.y, d.z)
        } else if a.y >= a.z {
            (2 + u32::from(d.y < 0.0), a.y, d.x, d.z)
        } else {
            (4 + u32::from(d.z < 0.0), a.z, d.x, d.y)
        };
        // (x/major + 1)·n/2 with one division.
        let half_n = self.half_n;
        let scale = half_n / major;
        let to_cell = |x: f32| ((x * scale + half_n) as u32).min(self.n - 1);
        CellPlace {
            face,
            u: to_cell(u),
            v: to_cell(v),
        }
    }

    /// Whether the cells at `places`, all on one face, and every cell of that face
    /// among them (the rectangle of columns and rows they span) list no sphere. The
    /// directions among some that fall at `places` (a segment between two, a
    /// parallelogram's corners) project into that rectangle: a face's pyramid is
    /// convex, and central projection takes the segment or the parallelogram to a
    /// segment or a convex quadrilateral with the projected ends or corners.
    #[inline]
    pub(super) fn lists_nothing_among(&self, places: &[CellPlace]) -> bool {
        let face = places[0].face;
        if places.iter().any(|p| p.face != face) {
            return false;
        }
        let span = |along: fn(&CellPlace) -> u32| {
            let values = places.iter().map(along);
            (values.clone().min().unwrap_or(0), values.max().unwrap_or(0))
        };
        let ((u0, u1), (v0, v1)) = (span(|p| p.u), span(|p| p.v));
        // A row of a face's cells is contiguous in the offsets: its columns `u0..=u1`
        // are empty when their first start equals their last end.
        (v0..=v1).all(|v| {
            let (first, last) = (
                cell_index(face, u0, v, self.n),
                cell_index(face, u1, v, self.n),
            );
            self.offsets[first] == self.offsets[last + 1]
        })
    }

    /// The spheres of a cell with their nearest distances, nearest first.
    #[inline]
    pub(super) fn candidates(&self, cell: usize) -> &[Listed<T>] {
        let (start, end) = (self.offsets[cell] as usize, self.offsets[cell + 1] as usize);
        &self.items[start..end]
    }
}

/// Where a direction falls in a grid ([`DirGrid::place`]): its face, and its cell's
/// column `u` and row `v` on that face.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) struct CellPlace {
    face: u32,
    u: u32,
    v: u32,
}

/// The cone of directions of each cell of a face (the same for all six faces in face
/// coordinates): its axis and the cosine of its half-angle, widened.
struct CellCones {
    n: u32,
    /// `⌈n/2⌉`: the cells of a quarter of the face per side.
    half_n: u32,
    /// Per (u, v) of the quarter `u, v < half_n`: unit axis in face coordinates
    /// (u, v, 1)/|…| and the cosine (bounded from below) and sine (from above) of the
    /// widened half-angle. The other quarters mirror it.
    quarter: Vec<(DVec3, f64, f64)>,
}

impl CellCones {
    /// The cones for `n` cells per side, computed once per process. The cache is not
    /// held while they are worked out: that work runs on the pool, where a thread
    /// waiting for it runs other jobs meanwhile, such as a build waiting for the cache.
    /// (Two builds may then work out the same cones; the first kept is shared.)
    fn shared(n: u32) -> Arc<CellCones> {
        static CACHE: Mutex<Vec<Arc<CellCones>>> = Mutex::new(Vec::new());
        let lock = || CACHE.lock().unwrap_or_else(|e| e.into_inner());
        let cached = |cache: &[Arc<CellCones>]| cache.iter().find(|c| c.n == n).cloned();
        if let Some(cones) = cached(&lock()) {
            return cones;
        }
        let cones = Arc::new(CellCones::new(n));
        let mut cache = lock();
        if let Some(first) = cached(&cache) {
            return first;
        }
        cache.push(cones.clone());
        cones
    }

    /// The cones of one quarter of the face: the cells mirror across the face's middle
    /// lines, and so do their cones, to the bit (`at(n − i) = −at(i)`). A quarter is
    /// fewer pages to fault in, and fewer cones to work out, for every `whitted render`.
    fn new(n: u32) -> Self {
        let at = |i: u32| f64::from(2 * i as i32 - n as i32) / f64::from(n);
        let cone = |u: u32, v: u32| {
            let corners = [
                DVec3::new(at(u), at(v), 1.0),
                DVec3::new(at(u + 1), at(v), 1.0),
                DVec3::new(at(u), at(v + 1), 1.0),
                DVec3::new(at(u + 1), at(v + 1), 1.0),
            ];
            let axis = (corners[0] + corners[3]).normalize();
            let cos = corners
                .iter()
                .map(|c| c.normalize().dot(axis))
                .fold(1.0f64, f64::min)
                .clamp(0.0, 1.0);
            let sin = (1.0 - cos * cos).sqrt();
            // Widened by a fraction of the cell, as queries' rounding lands near
            // borders: the half-angle θ grows by δ ≥ 0.05·θ + 10⁻⁶ (tan θ ≥ θ), and the
            // widened angle's cosine and sine are bounded without trigonometry, the
            // cosine from below and the sine from above (cos δ ≥ 1 − δ²/2, sin δ ≤ δ),
            // which only widens the cone further.
            let delta = 0.05 * sin / cos + 1e-6;
            (
                axis,
                cos * (1.0 - 0.5 * delta * delta) - sin * delta,
                sin + cos * delta,
            )
        };
        let half_n = n.div_ceil(2);
        let quarter = (0..half_n)
            .into_par_iter()
            .flat_map_iter(|v| (0..half_n).map(move |u| cone(u, v)))
            .collect();
        CellCones { n, half_n, quarter }
    }

    /// Cell `i` of a row or column as a cell of the quarter, and the sign that mirrors it.
    #[inline]
    fn mirror(&self, i: u32) -> (u32, f64) {
        if i < self.half_n {
            (i, 1.0)
        } else {
            (self.n - 1 - i, -1.0)
        }
    }

    /// Whether the cell's cone meets the sphere's cone.
    #[inline]
    fn meets(&self, face: u32, u: u32, v: u32, sphere: &SphereCone) -> bool {
        let ((qu, su), (qv, sv)) = (self.mirror(u), self.mirror(v));
        let (axis, cos_cell, sin_cell) = self.quarter[(qv * self.half_n + qu) as usize];
        let axis = from_face(face, axis * DVec3::new(su, sv, 1.0));
        // The angle between the axes must not exceed the sum of the half-angles. Both
        // are below 90° (a cell spans less than a face; a sphere around the centre is
        // in every cell and never gets here), so the sum is below 180° and its cosine
        // orders angles.
        let cos_between = sphere.axis.dot(axis);
        let cos_sum = cos_cell * sphere.cos - sin_cell * sphere.sin;
        cos_between >= cos_sum - 1e-9
    }
}

/// The cone of directions in which a sphere is seen from the centre.
struct SphereCone {
    axis: DVec3,
    cos: f64,
    sin: f64,
}

impl SphereCone {
    fn new(rel: DVec3, dist: f64, r: f64) -> Self {
        let sin = (r / dist).min(1.0);
        SphereCone {
            axis: rel / dist,
            cos: (1.0 - sin * sin).sqrt(),
            sin,
        }
    }
}

/// A face-coordinate vector (u, v, w along the face's outward axis) in world axes.
fn from_face(face: u32, f: DVec3) -> DVec3 {
    let w = if face.is_multiple_of(2) { f.z } else { -f.z };
    match face / 2 {
        0 => DVec3::new(w, f.x, f.y),
        1 => DVec3::new(f.x, w, f.y),
        _ => DVec3::new(f.x, f.y, w),
    }
}

#[inline]
fn cell_index(face: u32, u: u32, v: u32, n: u32) -> usize {
    ((face * n + v) * n + u) as usize
}

/// The one face in which the box `[lo, hi]` (relative to the centre) can be seen, when
/// it lies well inside that face's pyramid; `None` when it may be seen in several.
/// "Well inside" leaves every other face's [`face_rect`] empty: there the box's
/// coordinates are beyond ±1/(1 − 2·`WIDEN`), more than `WIDEN` past the face's edge.
fn only_face(lo: DVec3, hi: DVec3) -> Option<u32> {
    let far = lo.abs().max(hi.abs());
    let axis = far.max_position();
    // The box's nearest extent along the axis, on the side it lies.
    let near = if lo[axis] > 0.0 {
        lo[axis]
    } else if hi[axis] < 0.0 {
        -hi[axis]
    } else {
        return None;
    };
    let others = match axis {
        0 => far.y.max(far.z),
        1 => far.x.max(far.z),
        _ => far.x.max(far.y),
    };
    (others < near * (1.0 - 2.0 * WIDEN)).then(|| 2 * axis as u32 + u32::from(hi[axis] < 0.0))
}

/// The cells of `face` that the box `[lo, hi]` (relative to the centre) may be seen in,
/// as `[u0, u1, v0, v1]`, or `None` when the box is not seen in that face.
fn face_rect(face: u32, lo: DVec3, hi: DVec3, n: u32) -> Option<[u32; 4]> {
    let (b, c, axis, sign) = face_frame(face);
    // Coordinates with the face's axis pointing outwards.
    let (a_lo, a_hi) = if sign > 0.0 {
        (lo[axis], hi[axis])
    } else {
        (-hi[axis], -lo[axis])
    };
    if a_hi <= 0.0 {
        return None;
    }
    let range = |x_lo: f64, x_hi: f64| -> (f64, f64) {
        if a_lo <= 0.0 {
            // The box reaches the face plane: a → 0⁺ sends x/a to ±∞ unless x keeps
            // one sign, in which case the largest a bounds it on one side.
            let min = if x_lo >= 0.0 {
                x_lo / a_hi
            } else {
                f64::NEG_INFINITY
            };
            let max = if x_hi <= 0.0 {
                x_hi / a_hi
            } else {
                f64::INFINITY
            };
            return (min, max);
        }
        // x/a over the box: smallest with the largest a when x ≥ 0, and so on.
        let min = x_lo / if x_lo >= 0.0 { a_hi } else { a_lo };
        let max = x_hi / if x_hi >= 0.0 { a_lo } else { a_hi };
        (min, max)
    };
    cells_within(range(lo[b], hi[b]), range(lo[c], hi[c]), n)
}

/// The axes of a face's coordinates (u, v) and of its outward axis, and the sign that
/// turns the axis outwards.
fn face_frame(face: u32) -> (usize, usize, usize, f64) {
    let axis = (face / 2) as usize;
    let (b, c) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    (b, c, axis, sign)
}

/// The cells of `face` in which a sphere at `rel` (relative to the centre) of radius
/// `reach` is seen, when it lies in front of the face's plane by more than twice its
/// radius: the rectangle around its silhouette (the ellipse it projects to on the
/// face), bounded in each face coordinate by the two planes through the centre
/// tangent to the sphere. For a sphere off the face's axis it is tighter than its
/// box's rectangle ([`face_rect`]), which reaches out to the box's corners. `None`
/// for a sphere nearer the plane (there the bounds lose precision) or not seen in the
/// face.
fn silhouette_rect(face: u32, rel: DVec3, reach: f64, n: u32) -> Option<[u32; 4]> {
    let (b, c, axis, sign) = face_frame(face);
    let a = sign * rel[axis];
    if a <= 2.0 * reach {
        return None;
    }
    // The tangents from the centre to the circle of radius `reach` around (x, a), in
    // the plane of x and the face's axis: x/a ± the half-angle, as slopes. With a >
    // 2·reach, a² − reach² > 0.75·a² and the bounds carry an error of a few ε, far
    // below the widening.
    let denom = (a - reach) * (a + reach);
    let inv = 1.0 / denom;
    let range = |x: f64| {
        let spread = reach * (x * x + denom).sqrt();
        ((x * a - spread) * inv, (x * a + spread) * inv)
    };
    cells_within(range(rel[b]), range(rel[c]), n)
}

/// The cells of a face covering face coordinates `u` and `v` (ranges), widened by
/// [`WIDEN`]; `None` when that leaves the face.
fn cells_within(u: (f64, f64), v: (f64, f64), n: u32) -> Option<[u32; 4]> {
    let (u_lo, u_hi, v_lo, v_hi) = (u.0 - WIDEN, u.1 + WIDEN, v.0 - WIDEN, v.1 + WIDEN);
    if u_lo > 1.0 || u_hi < -1.0 || v_lo > 1.0 || v_hi < -1.0 {
        return None;
    }
    let to_cell = |x: f64| {
        let x = x.clamp(-1.0, 1.0);
        (((x + 1.0) * 0.5 * f64::from(n)) as u32).min(n - 1)
    };
    Some([to_cell(u_lo), to_cell(u_hi), to_cell(v_lo), to_cell(v_hi)])
}

#[cfg(test)]
mod tests {
    use glam::{DVec2, DVec3};

    use super::{
        cell_places, cell_ranges, coarser, face_rect, fewest_entries, most_entries, nearest_first,
        only_face, silhouette_rect, CellCones, DirGrid, Listed, ViewPyramid, COARSEST, ENTRIES_ANY,
        ENTRIES_PER_SPHERE, MOST_WIDE, SPHERES_PER_BUCKET, SPHERES_PER_RUN, WIDEN,
    };

    /// What a grid lists, against the spheres' geometry in `f64` and directions drawn at
    /// random (each placed in its cell by the queries' own [`DirGrid::cell`]): a sphere
    /// is listed in the cell of every direction it is seen in; a cell lists it only if
    /// it is seen within 0.6 of a cell's half-width of some direction of that cell (a
    /// cell's cone circumscribes its square, which reaches 0.45 of it beyond the
    /// square's sides); each entry's distance is the sphere's nearest distance rounded
    /// down by at most 3·10⁻⁶ relative; each cell's list runs nearest first; and the
    /// spheres around the centre are `always`, and only they.
    #[test]
    fn cells_list_the_spheres_seen_in_them_and_no_others() {
        let mut unit = crate::accel::tests::uniform(11);
        let mut direction = || {
            let (z, phi) = (2.0 * unit() - 1.0, std::f64::consts::TAU * unit());
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), z)
        };
        let centre = DVec3::new(0.3, -1.7, 2.2);
        let n = 8;
        // Seen at angular radii from 10⁻³ to 60 degrees, and four around the centre.
        let mut spheres = Vec::new();
        for k in 0..160 {
            let dist = 10f64.powf(-1.0 + 3.0 * (k as f64 / 160.0));
            let sin = 10f64
                .powf(-3.0 + 3.0 * ((k * 37 % 160) as f64 / 160.0))
                .min(0.87);
            spheres.push((centre + direction() * dist, dist * sin));
        }
        for r in [0.5, 3.0, 40.0] {
            spheres.push((centre + direction() * (0.7 * r), r));
        }
        // And one whose surface passes a ten-millionth of its radius beyond the centre.
        spheres.push((centre + direction() * (2.0 * (1.0 - 1e-7)), 2.0));
        // Directions on the cube's edges and corners, where two or three faces meet
        // and a face coordinate is ±1 exactly, each with a sphere seen around it, and a
        // tiny one (4·10⁻⁵ rad) seen across the edge or corner, with directions to it
        // from each side.
        let mut diagonals = Vec::new();
        for x in [-1.0, 0.0, 1.0] {
            for y in [-1.0, 0.0, 1.0] {
                for z in [-1.0, 0.0, 1.0] {
                    let d = DVec3::new(x, y, z).normalize();
                    if x * x + y * y + z * z >= 2.0 {
                        spheres.push((centre + d * 5.0, 0.5));
                        spheres.push((centre + d * 5.0, 2e-4));
                        let (e1, e2) = d.any_orthonormal_pair();
                        diagonals.push(d);
                        for e in [e1, -e1, e2, -e2] {
                            diagonals.push((d + e * 2e-5).normalize());
                        }
                    }
                }
            }
        }
        let grid = DirGrid::build(centre, &spheres, n, None).expect("within the bound");

        let mut samples: Vec<DVec3> = (0..400_000).map(|_| direction()).collect();
        samples.extend(diagonals);
        let mut by_cell = vec![Vec::new(); 6 * (n * n) as usize];
        for &d in &samples {
            by_cell[grid.cell(d.as_vec3())].push(d);
        }
        // Each cell its own directions: some in every one, about as many in each as its
        // solid angle (a corner cell's is 0.19 of a central one's at n = 8), up to 4x.
        let fewest = by_cell.iter().map(Vec::len).min().unwrap_or(0);
        let most = by_cell.iter().map(Vec::len).max().unwrap_or(0);
        assert!(
            fewest > 100 && most < 4 * 400_000 / by_cell.len(),
            "{fewest} to {most}"
        );
        let mut always: Vec<u32> = grid.always.clone();
        always.sort_unstable();
        let around: Vec<u32> = (0..spheres.len() as u32)
            .filter(|&k| {
                let (c, r) = spheres[k as usize];
                (c - centre).length() <= r
            })
            .collect();
        assert_eq!(always, around);

        let half_width = 1.0 / f64::from(n);
        let (mut entries, mut widest) = (0, 0.0f64);
        for (cell, seen) in by_cell.iter().enumerate() {
            let list = grid.candidates(cell);
            assert!(
                list.windows(2).all(|w| w[0].near <= w[1].near),
                "cell {cell}"
            );
            for (k, (c, r)) in spheres.iter().enumerate() {
                let rel = *c - centre;
                let dist = rel.length();
                if dist <= *r {
                    continue;
                }
                let (axis, half) = (rel / dist, (r / dist).asin());
                // How far outside the sphere's cone the cell's nearest direction lies.
                let outside = seen
                    .iter()
                    .map(|d| d.dot(axis).clamp(-1.0, 1.0).acos() - half)
                    .fold(f64::INFINITY, f64::min);
                let entry = list.iter().find(|e| e.k == k as u32);
                if outside < -1e-9 {
                    assert!(entry.is_some(), "cell {cell}: sphere {k} seen, not listed");
                }
                if let Some(&super::Listed { near, .. }) = entry {
                    entries += 1;
                    widest = widest.max(outside / half_width);
                    assert!(
                        outside <= 0.6 * half_width,
                        "cell {cell}: sphere {k} listed, {outside} outside"
                    );
                    let exact = dist - r;
                    let scale = dist + r + centre.abs().max_element();
                    assert!(
                        f64::from(near) <= exact && f64::from(near) >= exact - 3e-6 * scale,
                        "sphere {k}: {near} for {exact}"
                    );
                }
            }
        }
        println!("{entries} entries, the farthest {widest:.3} of a half-width outside");
        assert!(entries > 1500, "{entries} entries");
    }

    /// Grids built at once by several renders sharing one pool (the tests do, as may
    /// a program calling the library from several threads), each of a resolution not
    /// built before, all finish: no thread holds the cones' cache while the cones are
    /// worked out on the pool (a thread that waits for that work runs other jobs
    /// meanwhile, and one of them may be a build waiting for the cache: for ever).
    #[test]
    fn grids_built_at_once_by_renders_sharing_a_pool_finish() {
        let (done, finished) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .expect("a pool");
            std::thread::scope(|scope| {
                for _ in 0..4 {
                    scope.spawn(|| {
                        let spheres = [(DVec3::new(0.0, 0.0, 5.0), 1.0)];
                        for n in 300..360 {
                            let grid = pool.install(|| {
                                DirGrid::build(DVec3::ZERO, &spheres, n, None)
                                    .expect("within the bound")
                            });
                            assert!(grid.items.len() > 1, "the sphere is seen in several cells");
                        }
                    });
                }
            });
            done.send(()).expect("the test waits for the builds");
        });
        let waited = finished.recv_timeout(std::time::Duration::from_secs(120));
        assert!(waited.is_ok(), "the builds did not finish in 2 minutes");
    }

    /// Boxes of every shape and place around the centre: a direction, a distance from
    /// 0.01 to 100, half-extents per axis from 10⁻⁵ to 2 times the distance (some hold
    /// the centre), as `(lo, hi)` relative to the centre.
    fn random_boxes(seed: u64, count: usize) -> Vec<(DVec3, DVec3)> {
        let mut unit = crate::accel::tests::uniform(seed);
        (0..count)
            .map(|_| {
                let (z, phi) = (2.0 * unit() - 1.0, std::f64::consts::TAU * unit());
                let s = (1.0 - z * z).sqrt();
                let dist = 10f64.powf(-2.0 + 4.0 * unit());
                let centre = DVec3::new(s * phi.cos(), s * phi.sin(), z) * dist;
                let mut half = || dist * 10f64.powf(-5.0 + 5.3 * unit());
                let half = DVec3::new(half(), half(), half());
                (centre - half, centre + half)
            })
            .collect()
    }

    /// A face's axis, its sign, and the two axes across it (u, v), as `face_rect` and
    /// `from_face` number them.
    /// The silhouette's rectangle of a sphere in front of a face: every direction to a
    /// point of the sphere falls in one of its cells, and it reaches no further than
    /// the widening past the farthest of those directions; for a sphere nearer the
    /// face's plane than twice its radius there is none.
    #[test]
    fn silhouette_rect_holds_the_sphere_s_directions_and_no_more() {
        let n = 64u32;
        let mut unit = crate::accel::tests::uniform(12);
        let (mut sphere_points, mut near_the_plane) = (0, 0);
        for _ in 0..3_000 {
            let face = (unit() * 6.0) as u32;
            let (a, s, b, c) = face_axes(face);
            let dist = 0.5 + 50.0 * unit();
            let r = dist * 0.7 * unit().powi(3);
            let mut rel = DVec3::ZERO;
            rel[a] = s * dist;
            rel[b] = dist * (1.8 * unit() - 0.9);
            rel[c] = dist * (1.8 * unit() - 0.9);
            let Some([u0, u1, v0, v1]) = silhouette_rect(face, rel, r, n) else {
                assert!(dist <= 2.0 * r, "{rel} {r}: no rectangle");
                near_the_plane += 1;
                continue;
            };
            // Points of the sphere, the rim seen from the centre among them: the
            // tangent directions are the extremes.
            let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(-f64::INFINITY));
            for _ in 0..400 {
                let (z, phi) = (2.0 * unit() - 1.0, std::f64::consts::TAU * unit());
                let w = DVec3::new(
                    (1.0 - z * z).sqrt() * phi.cos(),
                    (1.0 - z * z).sqrt() * phi.sin(),
                    z,
                );
                let p = rel + w * r;
                let t = DVec2::new(p[b], p[c]) / (s * p[a]);
                lo = lo.min(t);
                hi = hi.max(t);
                sphere_points += 1;
            }
            let cell = |x: f64| (((x + 1.0) * 0.5 * f64::from(n)) as u32).min(n - 1);
            let (su0, su1, sv0, sv1) = (cell(lo.x), cell(hi.x), cell(lo.y), cell(hi.y));
            assert!(
                u0 <= su0 && su1 <= u1 && v0 <= sv0 && sv1 <= v1,
                "{rel} {r}: points out"
            );
            let reach = |x: f64| cell(x + WIDEN);
            let short = |x: f64| cell(x - WIDEN);
            assert!(
                u0 >= short(lo.x).saturating_sub(1) && u1 <= reach(hi.x) + 1,
                "{rel} {r}: u {u0}..{u1} for points in {su0}..{su1}"
            );
            assert!(
                v0 >= short(lo.y).saturating_sub(1) && v1 <= reach(hi.y) + 1,
                "{rel} {r}: v {v0}..{v1} for points in {sv0}..{sv1}"
            );
        }
        assert!(
            sphere_points > 500_000 && near_the_plane > 100,
            "{near_the_plane}"
        );
    }

    /// Where a sphere is seen in one face only and lies more than twice its reach in
    /// front of it, its silhouette's rectangle lies inside its box's (so `cells_of`
    /// takes it alone): radii from a third of the distance down to 10⁻¹² of it, and
    /// distances from 10⁻³ to 10⁶.
    #[test]
    fn silhouette_rect_lies_inside_the_box_s_rect() {
        let n = 256u32;
        let mut unit = crate::accel::tests::uniform(31);
        let mut compared = 0;
        for _ in 0..200_000 {
            let face = (unit() * 6.0) as u32;
            let (a, s, b, c) = face_axes(face);
            let dist = 10f64.powf(-3.0 + 9.0 * unit());
            let mut rel = DVec3::ZERO;
            rel[a] = s * dist;
            rel[b] = dist * (2.0 * unit() - 1.0);
            rel[c] = dist * (2.0 * unit() - 1.0);
            let reach = dist * 10f64.powf(-12.0 + 11.5 * unit());
            let (lo, hi) = (rel - DVec3::splat(reach), rel + DVec3::splat(reach));
            if only_face(lo, hi) != Some(face) {
                continue;
            }
            let Some([u0, u1, v0, v1]) = silhouette_rect(face, rel, reach, n) else {
                continue;
            };
            let [bu0, bu1, bv0, bv1] = face_rect(face, lo, hi, n).expect("seen in the face");
            assert!(
                bu0 <= u0 && u1 <= bu1 && bv0 <= v0 && v1 <= bv1,
                "{rel} {reach}: silhouette {:?} box {:?}",
                [u0, u1, v0, v1],
                [bu0, bu1, bv0, bv1]
            );
            compared += 1;
        }
        assert!(compared > 100_000, "{compared}");
    }

    /// A cell's cone holds every direction through the cell widened by 5% of its
    /// half-angle and 10⁻⁶: its cosine is at most, and its sine at least, those of that
    /// angle (worked out with trigonometry, the corner farthest from the axis giving
    /// the half-angle), and hardly wider than the widening its bounds take, 0.05·tan θ
    /// + 10⁻⁶ (tan θ ≥ θ).
    #[test]
    fn cell_cones_hold_the_cells_widened() {
        for n in [1, 2, 3, 12, 64, 256] {
            let cones = CellCones::new(n);
            let at = |i: u32| f64::from(2 * i as i32 - n as i32) / f64::from(n);
            for v in 0..cones.half_n {
                for u in 0..cones.half_n {
                    let (axis, cos, sin) = cones.quarter[(v * cones.half_n + u) as usize];
                    let half = [(u, v), (u + 1, v), (u, v + 1), (u + 1, v + 1)]
                        .map(|(a, b)| {
                            DVec3::new(at(a), at(b), 1.0)
                                .normalize()
                                .angle_between(axis)
                        })
                        .into_iter()
                        .fold(0.0f64, f64::max);
                    let least = half * 1.05 + 1e-6;
                    assert!(cos <= least.cos() && sin >= least.sin(), "n {n} ({u}, {v})");
                    // The bound's own widening, 0.05·tan θ + 10⁻⁶, and its terms of
                    // second order: a hundredth of it in the cosine's angle, a tenth in
                    // the sine's.
                    let widening = 0.05 * half.tan() + 1e-6;
                    let wider = |by: f64| half + widening * by;
                    assert!(cos >= wider(1.01).cos(), "n {n} ({u}, {v}): cosine");
                    assert!(sin <= wider(1.1).sin(), "n {n} ({u}, {v}): sine");
                }
            }
        }
    }

    fn face_axes(face: u32) -> (usize, f64, usize, usize) {
        let axis = (face / 2) as usize;
        let (b, c) = [(1, 2), (0, 2), (0, 1)][axis];
        (axis, if face.is_multiple_of(2) { 1.0 } else { -1.0 }, b, c)
    }

    fn corners(lo: DVec3, hi: DVec3) -> [DVec3; 8] {
        std::array::from_fn(|k| {
            DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        })
    }

    /// `only_face` names a face for every box whose coordinates across that face stay
    /// below (1 − 3·`WIDEN`) times its every distance along the face's axis, and names
    /// a face only for a box wholly inside that face's pyramid, whose every other
    /// face's `face_rect` is then empty (the queries look at no other face for it).
    #[test]
    fn only_face_names_the_one_face_a_box_is_seen_in() {
        let (mut inside, mut named, mut straddling) = (0, 0, 0);
        for (lo, hi) in random_boxes(5, 200_000) {
            let corners = corners(lo, hi);
            let clearly_in = (0..6).find(|&face| {
                let (a, s, b, c) = face_axes(face);
                let near = corners
                    .iter()
                    .map(|p| s * p[a])
                    .fold(f64::INFINITY, f64::min);
                let across = corners
                    .iter()
                    .map(|p| p[b].abs().max(p[c].abs()))
                    .fold(0.0, f64::max);
                near > 0.0 && across < near * (1.0 - 3.0 * WIDEN)
            });
            let got = only_face(lo, hi);
            if let Some(face) = clearly_in {
                inside += 1;
                assert_eq!(got, Some(face), "box {lo} {hi}");
            }
            let Some(face) = got else {
                straddling += usize::from(clearly_in.is_none());
                continue;
            };
            named += 1;
            let (a, s, b, c) = face_axes(face);
            for p in corners {
                assert!(
                    s * p[a] > 0.0 && p[b].abs().max(p[c].abs()) < s * p[a],
                    "box {lo} {hi}: corner {p} not in face {face}"
                );
            }
            for other in (0..6).filter(|&g| g != face) {
                assert_eq!(
                    face_rect(other, lo, hi, 8),
                    None,
                    "box {lo} {hi}, face {other}"
                );
            }
        }
        println!("{inside} boxes clearly inside a face, {named} named, {straddling} not");
        assert!(
            inside > 20_000 && straddling > 20_000,
            "{inside} {straddling}"
        );
    }

    /// `face_rect` covers the cell of every direction in which a box is seen on that
    /// face (its corners and 32 random points of it), and is `None` for a face that
    /// the box lies wholly behind, or wholly beyond one edge of (by 1%, a plane through
    /// the centre that every corner is past).
    #[test]
    fn face_rect_covers_the_cells_a_box_is_seen_in_and_no_face_it_is_not() {
        let n = 8u32;
        let mut unit = crate::accel::tests::uniform(6);
        let (mut covered, mut behind, mut beyond) = (0, 0, 0);
        for (lo, hi) in random_boxes(7, 20_000) {
            let corners = corners(lo, hi);
            let mut points = corners.to_vec();
            points.extend((0..32).map(|_| lo + (hi - lo) * DVec3::new(unit(), unit(), unit())));
            for face in 0..6 {
                let rect = face_rect(face, lo, hi, n);
                let (a, s, b, c) = face_axes(face);
                let cell = |x: f64| (((x + 1.0) * 0.5 * f64::from(n)) as u32).min(n - 1);
                for p in &points {
                    let w = s * p[a];
                    if w > 0.0 && p[b].abs() <= w && p[c].abs() <= w {
                        let (u, v) = (cell(p[b] / w), cell(p[c] / w));
                        covered += 1;
                        assert!(
                            rect.is_some_and(|[u0, u1, v0, v1]| {
                                (u0..=u1).contains(&u) && (v0..=v1).contains(&v)
                            }),
                            "box {lo} {hi}: {p} in face {face} cell ({u}, {v}), rect {rect:?}"
                        );
                    }
                }
                let all_behind = corners.iter().all(|p| s * p[a] <= 0.0);
                let past_an_edge = [(b, 1.0), (b, -1.0), (c, 1.0), (c, -1.0)]
                    .iter()
                    .any(|&(x, sign)| corners.iter().all(|p| sign * p[x] > 1.01 * s * p[a]));
                if all_behind || past_an_edge {
                    behind += usize::from(all_behind);
                    beyond += usize::from(past_an_edge && !all_behind);
                    assert_eq!(rect, None, "box {lo} {hi}, face {face}");
                }
            }
        }
        println!("{covered} points seen, {behind} faces behind boxes, {beyond} beyond");
        assert!(covered > 100_000 && behind > 10_000 && beyond > 10_000);
    }

    /// A sphere whose box spans two cells on one side of a face but whose silhouette
    /// lies in one cell is listed in that cell only: the box of the sphere of radius 1
    /// at (1.1, 1.25, 10) reaches v = 2.25/9 = 0.25 (a border of the 8 cells a side,
    /// 0.25 wide), its silhouette only v = (12.5 + √100.5625)/99 ≈ 0.2276; the second
    /// sphere is the first with u and v swapped. (The cells' cones alone would keep
    /// the neighbour across the border.)
    #[test]
    fn a_ball_whose_box_crosses_a_border_its_silhouette_does_not_fills_one_cell() {
        let spheres = [
            (DVec3::new(1.1, 1.25, 10.0), 1.0),
            (DVec3::new(1.25, 1.1, 10.0), 1.0),
        ];
        let n = 8;
        let grid = DirGrid::build(DVec3::ZERO, &spheres, n, None).expect("within the bound");
        for (k, &(c, _)) in spheres.iter().enumerate() {
            let cells: Vec<usize> = (0..6 * (n * n) as usize)
                .filter(|&cell| grid.candidates(cell).iter().any(|e| e.k == k as u32))
                .collect();
            assert_eq!(cells, [grid.cell(c.as_vec3())], "sphere {k}");
        }
    }

    /// Spheres at one nearest distance (copies of one sphere, and copies of another
    /// exactly as far in another direction of the cell: 41 = |(0, 9, 40)|) are listed
    /// in the order of their indices, after the nearer ones and before the farther
    /// ones: the order is the distance, then the index, so the same scene always
    /// gives the same lists.
    #[test]
    fn spheres_as_near_are_listed_in_index_order() {
        let centre = DVec3::new(1.0, 2.0, 3.0);
        let ahead = DVec3::new(0.0, 0.0, 41.0);
        let mut spheres = Vec::new();
        for k in 0..40 {
            spheres.push(match k % 4 {
                0 => (centre + ahead, 1.0),
                1 => (centre + DVec3::new(0.0, 9.0, 40.0), 1.0),
                2 => (centre + ahead * 2.0, 1.0),
                _ => (centre + ahead * 0.5, 0.25),
            });
        }
        let grid = DirGrid::build(centre, &spheres, 4, None).expect("within the bound");
        let list = grid.candidates(grid.cell(glam::Vec3::Z));
        let ks: Vec<u32> = list.iter().map(|e| e.k).collect();
        let mut want: Vec<u32> = (0..40).filter(|k| k % 4 == 3).collect();
        want.extend((0..40).filter(|k| k % 4 < 2));
        want.extend((0..40).filter(|k| k % 4 == 2));
        assert_eq!(ks, want);
    }

    /// `nearest_first` orders the spheres as a stable sort by their rounded nearest
    /// distance does, in `total_cmp`'s order: over many buckets, with ties, spheres
    /// around the centre (distances below zero, all of them within a few buckets'
    /// width of zero in one case), one far away (most buckets then empty) and spheres
    /// the view leaves out.
    #[test]
    fn nearest_first_is_a_stable_sort_by_the_nearest_distance() {
        let mut unit = crate::accel::tests::uniform(41);
        let centre = DVec3::new(-3.0, 1.0, 2.0);
        let many = 20 * SPHERES_PER_BUCKET;
        let cases = [
            (1, 50.0, false),
            (7, 50.0, true),
            (3 * SPHERES_PER_BUCKET + 5, 50.0, true),
            (many, 50.0, false),
            (many, 50.0, true),
            (many, 1.0, false),
        ];
        for (count, spread, far_one) in cases {
            let mut spheres: Vec<(DVec3, f64)> = (0..count)
                .map(|k| {
                    let dir = (DVec3::new(unit(), unit(), unit()) - 0.5).normalize_or(DVec3::Z);
                    let (dist, r) = match k % 5 {
                        0 => (0.5 * spread, 0.5), // ties
                        1 => (0.1, 0.4 * unit()), // around the centre, some
                        _ => (spread * unit(), 0.01 + unit()),
                    };
                    (centre + dir * dist, r)
                })
                .collect();
            if far_one {
                spheres[count / 2] = (centre + DVec3::new(0.0, 1e7, 0.0), 1.0);
            }
            // A film a unit ahead along −z, 2 wide and 2 high: a quarter of the directions.
            let film = DVec3::new(-1.0, -1.0, -1.0);
            let view = ViewPyramid::new(centre, centre + film, 2.0 * DVec3::X, 2.0 * DVec3::Y)
                .expect("a proper pyramid");
            for view in [None, Some(&view)] {
                let sorted = nearest_first(centre, &spheres, view, |c, r| (c, r));
                let mut want: Vec<(u32, f32)> = spheres
                    .iter()
                    .enumerate()
                    .filter(|&(_, &(c, r))| view.is_none_or(|v| v.may_see(c - centre, r)))
                    .map(|(k, &(c, r))| {
                        let dist = (c - centre).length();
                        let d = (dist - r) - 1e-6 * (dist + r + centre.abs().max_element());
                        (k as u32, super::super::round_down(d))
                    })
                    .collect();
                want.sort_by(|a, b| a.1.total_cmp(&b.1));
                let got: Vec<(u32, f32)> = sorted.iter().map(|(_, e)| (e.k, e.near)).collect();
                assert_eq!(got.len(), want.len(), "count {count}");
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        g.0 == w.0 && g.1.to_bits() == w.1.to_bits(),
                        "count {count}, place {i}: {g:?} against {w:?}"
                    );
                }
                for ((c, r), e) in &sorted {
                    assert_eq!((*c, *r), spheres[e.k as usize]);
                    assert_eq!(e.data, spheres[e.k as usize]);
                }
            }
        }
    }

    /// Built with wide spheres apart, a grid lists a sphere seen at an angular radius
    /// of sine [`WIDE_SIN`] or more in `wide`, nearest first, and in no cell, and one
    /// just under it in cells as before; with one more wide sphere than [`MOST_WIDE`],
    /// or built without, every sphere is in the cells. `fewest_entries` counts the
    /// wide ones as none when they may be apart.
    #[test]
    fn wide_spheres_are_listed_apart_up_to_their_most() {
        let centre = DVec3::new(1.0, -2.0, 0.5);
        let at = |dir: DVec3, dist: f64, sin: f64| (centre + dir.normalize() * dist, dist * sin);
        // Wide at sines 0.5 (exactly, in binary) and 0.9, nearest the farther; then one
        // at 0.499 and small ones.
        let mut spheres = vec![
            at(DVec3::new(0.0, 0.0, 1.0), 8.0, 0.5),
            at(DVec3::new(1.0, 0.2, 0.0), 3.0, 0.9),
            at(DVec3::new(-1.0, 0.5, 0.3), 5.0, 0.499),
        ];
        for k in 0..20 {
            spheres.push(at(DVec3::new(f64::from(k) - 9.5, 3.0, -2.0), 20.0, 0.01));
        }
        let n = 16;
        let build = |spheres: &[(DVec3, f64)], apart| {
            DirGrid::build_with(centre, spheres, n, None, |_, _| (), usize::MAX, apart)
                .expect("no bound")
        };
        let in_cells = |g: &DirGrid, k: u32| g.items.iter().filter(|e| e.k == k).count();
        let grid = build(&spheres, true);
        let wide: Vec<u32> = grid.wide.iter().map(|e| e.k).collect();
        assert_eq!(wide, [1, 0]);
        assert_eq!((in_cells(&grid, 0), in_cells(&grid, 1)), (0, 0));
        assert!(in_cells(&grid, 2) > 1);
        assert!((3..spheres.len() as u32).all(|k| in_cells(&grid, k) >= 1));
        let together = build(&spheres, false);
        assert!(together.wide.is_empty() && in_cells(&together, 0) > 1);
        assert_eq!(
            grid.items.len() + in_cells(&together, 0) + in_cells(&together, 1),
            together.items.len()
        );
        // Apart, the two wide spheres count none and the others as they would alone.
        let fewest = fewest_entries(centre, &spheres, n, None, true);
        let alone = fewest_entries(centre, &spheres[2..], n, None, false);
        assert!((fewest - alone).abs() <= 1e-9 * alone, "{fewest} {alone}");
        assert!(fewest >= 21.0 && fewest <= grid.items.len() as f64);
        // Wide spheres, one more than are kept apart: all in the cells.
        let mut crowd = spheres.clone();
        for k in 0..MOST_WIDE - 1 {
            crowd.push(at(
                DVec3::new(f64::from(k as u32) - 3.0, -4.0, 1.0),
                40.0,
                0.6,
            ));
        }
        let crowded = build(&crowd, true);
        assert!(crowded.wide.is_empty());
        assert_eq!(crowded.items.len(), build(&crowd, false).items.len());
        // As many as are kept apart: all apart.
        crowd.pop();
        assert_eq!(build(&crowd, true).wide.len(), MOST_WIDE);
    }

    /// The bound counts every entry of every run: a grid of `E` entries is built
    /// within a bound of `E`, the same as without one, and not within `E − 1` (spheres
    /// over several runs of the build, from small to ones seen over many cells).
    #[test]
    fn a_grid_is_built_within_a_bound_of_its_entries_and_not_below() {
        let mut unit = crate::accel::tests::uniform(5);
        let spheres: Vec<(DVec3, f64)> = (0..3 * SPHERES_PER_RUN + 17)
            .map(|_| {
                let c = DVec3::new(unit(), unit(), unit()) * 20.0 - DVec3::splat(10.0);
                (c, 0.01 + 0.5 * unit().powi(3))
            })
            .collect();
        let centre = DVec3::new(0.5, 0.25, -0.125);
        let build = |bound| within(centre, &spheres, 32, bound);
        let all = build(usize::MAX).expect("no bound");
        let entries = all.items.len();
        assert!(entries > 2 * spheres.len(), "{entries} entries");
        let within = build(entries).expect("a bound of its entries");
        assert_eq!(within.offsets, all.offsets);
        let ks = |g: &DirGrid| g.items.iter().map(|e| e.k).collect::<Vec<_>>();
        assert_eq!(ks(&within), ks(&all));
        assert!(build(entries - 1).is_none());
    }

    /// The ranges that fill a grid's cells on several threads cover every cell and
    /// entry once, in order, each range's entries those of its cells, and share the
    /// entries about evenly: no range more than a cell's entries past its share.
    #[test]
    fn cell_ranges_cover_the_cells_in_order_and_share_the_entries() {
        let mut rng = rand_mt::Mt64::new(3);
        for (cells, parts) in [(1, 1), (1, 3), (10, 2), (1000, 2), (1000, 3), (5000, 7)] {
            // Cells of 0 to 20 entries, a tenth of them crowded (up to 200); the
            // offsets hold each cell's end, and one more past the last.
            let mut end = 0u32;
            let mut offsets: Vec<u32> = (0..=cells)
                .map(|c| {
                    let r = rng.next_u64();
                    if c < cells {
                        let crowd = if r.is_multiple_of(10) {
                            (r >> 8) % 200
                        } else {
                            0
                        };
                        end += (r % 21 + crowd) as u32;
                    }
                    end
                })
                .collect();
            let ends = offsets.clone();
            let entry = Listed {
                k: 0,
                near: 0.0,
                data: (),
            };
            let mut items = vec![entry; end as usize];
            let widest = ends
                .windows(2)
                .map(|w| w[1] - w[0])
                .max()
                .unwrap_or(0)
                .max(ends[0]);
            let ranges = cell_ranges(&mut offsets, &mut items, parts);
            assert_eq!(ranges.len(), parts);
            let (mut cell, mut item) = (0u32, 0u32);
            for (p, range) in ranges.iter().enumerate() {
                assert_eq!(
                    (range.first_cell, range.first_item),
                    (cell, item),
                    "part {p}"
                );
                cell += range.offsets.len() as u32;
                item += range.items.len() as u32;
                if let Some(&last) = range.offsets.last() {
                    assert_eq!(
                        last, item,
                        "part {p}: its entries end at its last cell's end"
                    );
                }
                let share = u64::from(end) / parts as u64;
                assert!(
                    range.items.len() as u64 <= share + u64::from(widest),
                    "part {p}: {} entries, a share of {share}",
                    range.items.len()
                );
            }
            assert_eq!((cell as usize, item), (cells + 1, end));
        }
    }

    /// The grid of `n` cells a side around `centre` with at most `bound` entries, no
    /// coarser one.
    fn within(centre: DVec3, spheres: &[(DVec3, f64)], n: u32, bound: usize) -> Option<DirGrid> {
        let sorted = nearest_first(centre, spheres, None, |_, _| ());
        DirGrid::build_within(centre, &sorted, n, bound, false)
    }

    /// `count` balls of radius `r` at distance `dist` from the origin, spread evenly
    /// over the directions.
    fn ring_of_balls(count: usize, dist: f64, r: f64) -> Vec<(DVec3, f64)> {
        let directions = crate::accel::tests::even_directions(count);
        directions.into_iter().map(|d| (d * dist, r)).collect()
    }

    /// The entries of `n` cells a side that balls of angular radius asin(`r`/`dist`)
    /// fill on average: each the fraction (1 − cos θ)/2 of the 6n² cells.
    fn average_entries(count: usize, dist: f64, r: f64, n: u32) -> f64 {
        let fraction = (1.0 - (1.0 - (r / dist).powi(2)).sqrt()) / 2.0;
        count as f64 * fraction * 6.0 * f64::from(n * n)
    }

    /// Balls crowding the centre, each seen over a seventh of the sky, would fill more
    /// cells than the bound allows: their grid comes at half the resolution, where a
    /// ball fills a quarter as many; ten times as many of them fill even the coarsest
    /// grid past the bound, and get none. Small balls farther out get the grid asked
    /// for.
    #[test]
    fn crowding_balls_get_a_coarser_grid_or_none() {
        let n = 128;
        let (dist, r) = (1.45, 1.0);
        let crowd = ring_of_balls(600, dist, r);
        let bound = most_entries(crowd.len());
        assert_eq!(bound, ENTRIES_ANY + ENTRIES_PER_SPHERE * 600);
        assert!(average_entries(600, dist, r, n) > 1.5 * bound as f64);
        assert!(average_entries(600, dist, r, n / 2) < 0.7 * bound as f64);
        let grid = DirGrid::build(DVec3::ZERO, &crowd, n, None).expect("a coarser grid");
        assert_eq!(grid.n, n / 2);
        assert!(grid.items.len() <= bound);

        let crowd = ring_of_balls(6000, dist, r);
        let bound = most_entries(crowd.len()) as f64;
        assert!(average_entries(6000, dist, r, COARSEST) > 1.1 * bound);
        assert!(DirGrid::build(DVec3::ZERO, &crowd, n, None).is_none());

        let small = ring_of_balls(600, 40.0, 0.1);
        let grid = DirGrid::build(DVec3::ZERO, &small, n, None).expect("small balls fit");
        assert_eq!(grid.n, n);
    }

    /// The skip of coarser grids relies on `fewest_entries` never exceeding the entries
    /// a grid lists: for balls from tiny to ones filling half the sky, near and far, at
    /// every resolution of the ladder.
    #[test]
    fn fewest_entries_is_at_most_the_entries_listed() {
        let mut unit = crate::accel::tests::uniform(23);
        let centre = DVec3::new(0.25, -0.5, 0.75);
        for trial in 0..12 {
            let spheres: Vec<(DVec3, f64)> = (0..40 + 30 * trial)
                .map(|_| {
                    let dir = DVec3::new(unit(), unit(), unit()) * 2.0 - DVec3::ONE;
                    let dist = 10f64.powf(2.0 * unit() - 1.0);
                    let sin = 10f64.powf(-3.0 * unit()).min(0.999);
                    (centre + dir.normalize_or(DVec3::X) * dist, dist * sin)
                })
                .collect();
            for n in [32, 64, 96, 128] {
                let fewest = fewest_entries(centre, &spheres, n, None, false);
                let grid = within(centre, &spheres, n, usize::MAX).expect("no bound");
                assert!(
                    fewest <= grid.items.len() as f64,
                    "trial {trial}, n {n}: {fewest} > {}",
                    grid.items.len()
                );
            }
        }
    }

    /// `fewest_entries` by hand: a ball of angular radius θ counts its solid angle
    /// 4π·sin²(θ/2) over the largest cell's (2/n)² steradians, less 1%; a small far
    /// ball counts 1 and a ball around the centre 0; with a view, only the balls it
    /// may see count. And for crowding balls the count is within a few times the
    /// entries their grid lists, so that the skip it decides is worth deciding.
    #[test]
    fn fewest_entries_counts_solid_angles_in_largest_cells() {
        let n = 64;
        let largest_cell = (2.0 / f64::from(n)).powi(2);
        let by_hand = |sin_theta: f64| {
            let half = sin_theta.asin() / 2.0;
            0.99 * 4.0 * std::f64::consts::PI * half.sin().powi(2) / largest_cell
        };
        let one = by_hand(0.5); // radius 1 at 2
        let half = by_hand(0.25); // radius 0.5 at 2
        let centre = DVec3::new(5.0, -3.0, -1.0);
        let ahead = (centre + DVec3::new(0.0, 0.0, -2.0), 1.0);
        let far_small = (centre + DVec3::new(0.0, 100.0, 0.0), 0.01);
        let around = (centre + DVec3::new(0.1, 0.0, 0.0), 1.0);
        let behind = (centre + DVec3::new(0.0, 0.0, 2.0), 0.5);
        let count =
            |spheres: &[(DVec3, f64)], view| fewest_entries(centre, spheres, n, view, false);
        let close = |got: f64, want: f64| (got - want).abs() <= 1e-9 * want;
        assert!(
            close(count(&[ahead], None), one),
            "{}",
            count(&[ahead], None)
        );
        assert_eq!(count(&[far_small], None), 1.0);
        assert_eq!(count(&[around], None), 0.0);
        let all = [ahead, far_small, around, behind];
        assert!(close(count(&all, None), one + half + 1.0));
        // Looking down −z through a film at distance 1: the ball behind is not seen.
        let view = crate::accel::ViewPyramid::new(
            centre,
            centre + DVec3::new(-1.0, -1.0, -1.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        )
        .expect("a pyramid");
        assert!(close(count(&all, Some(&view)), one));

        let crowd = ring_of_balls(300, 1.45, 1.0);
        let fewest = fewest_entries(DVec3::ZERO, &crowd, n, None, false);
        let listed = within(DVec3::ZERO, &crowd, n, usize::MAX)
            .expect("no bound")
            .items
            .len() as f64;
        assert!(
            fewest <= listed && listed <= 4.0 * fewest,
            "{fewest} {listed}"
        );
    }

    /// A grid's cells count against its bound in its entries' size (6n² + 1 offsets of
    /// 4 bytes): with room for the cells and the entries a build gives the grid asked
    /// for, with one place less the coarser one, and with room for the coarsest's
    /// cells but not its entries none.
    #[test]
    fn cells_count_against_the_bound_in_the_entries_size() {
        assert_eq!(cell_places(32, 32), 768); // 6,145 · 4 / 32 = 768.1
        assert_eq!(cell_places(256, 8), 196_608); // 393,217 · 4 / 8 = 196,608.5
        assert_eq!(cell_places(64, 4), 24_577);
        let (n, balls) = (64, ring_of_balls(100, 40.0, 0.1));
        let build =
            |bound| DirGrid::build_with(DVec3::ZERO, &balls, n, None, |_, _| (), bound, false);
        let all = within(DVec3::ZERO, &balls, n, usize::MAX).expect("no bound");
        let needs = all.items.len() + cell_places(n, 8);
        assert_eq!(build(needs).map(|g| g.n), Some(n));
        assert_eq!(build(needs - 1).map(|g| g.n), Some(n / 2));
        assert!(build(cell_places(COARSEST, 8) + balls.len() - 1).is_none());
    }

    /// A crowded grid falls back to halves of its resolution, finest first, down to 32
    /// cells a side and no further, and to no fewer cells than spheres.
    #[test]
    fn crowded_grids_fall_back_to_halves_down_to_the_coarsest() {
        let ladder = |n| coarser(n, 0).collect::<Vec<u32>>();
        // 6·64² = 24,576 cells, 6·128² = 98,304.
        assert_eq!(coarser(256, 24_576).collect::<Vec<u32>>(), [128, 64]);
        assert_eq!(coarser(256, 24_577).collect::<Vec<u32>>(), [128]);
        assert_eq!(coarser(256, 98_305).count(), 0);
        assert_eq!(COARSEST, 32);
        assert_eq!(ladder(384), [192, 96, 48]);
        assert_eq!(ladder(256), [128, 64, 32]);
        assert_eq!(ladder(128), [64, 32]);
        assert_eq!(ladder(64), [32]);
        assert!(ladder(63).is_empty());
        assert!(ladder(12).is_empty());
    }

    /// A build stops at the first look at the shared count that finds it past the
    /// bound, and gives no grid even when no other run adds to it: 1,500 balls each
    /// seen in one cell only (tiny, on the cells' middle directions), in one run of
    /// the build, whose count is looked at after every 1,024 entries.
    #[test]
    fn a_build_whose_count_reaches_the_bound_and_goes_on_gives_no_grid() {
        let n = 32u32;
        let middle = |i: u32| (2.0 * f64::from(i) + 1.0) / f64::from(n) - 1.0;
        let spheres: Vec<(DVec3, f64)> = (0..1500u32)
            .map(|k| {
                let (u, v) = (middle(k % n), middle(k / n % n));
                let z = if k < n * n { 1.0 } else { -1.0 };
                (DVec3::new(u, v, z).normalize() * 10.0, 1e-4)
            })
            .collect();
        let build = |bound| within(DVec3::ZERO, &spheres, n, bound);
        let all = build(usize::MAX).expect("no bound");
        assert_eq!(all.items.len(), spheres.len(), "one cell each");
        assert!(build(1500).is_some());
        assert!(build(1024).is_none());
        assert!(build(1023).is_none());
    }
}
