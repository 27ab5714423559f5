//! The culling of the fast path (the `f32` boxes of the hierarchy, the widened `f32`
//! sphere tests, the directional grids around the eye and the lights) never loses a
//! hit or an occluder, for spheres from radius 1e-3 to 1e5 scattered up to 1e4 from the
//! origin. Every answer is compared with a brute-force `f64` test of every sphere;
//! cases that are ambiguous at `f64` precision (near-tangent rays, near-ties, crossings
//! at the ends of a shadow segment) are left out and counted.

use std::cell::RefCell;

use glam::{DVec3, Vec3};
use proptest::prelude::*;

use super::*;
use crate::accel::{EyeArea, Hit, InsideLists, Spheres};
use crate::scene::Sphere;

/// Random spheres: radius 10^U(−3,3), centre 10^U(−1,4) from the origin.
pub(super) fn world() -> impl Strategy<Value = Vec<Sphere>> {
    prop::collection::vec(
        (
            log_uniform(-3.0, 3.0),
            log_uniform(-1.0, 4.0),
            unit_vector(),
        ),
        1..300,
    )
    .prop_map(|v| {
        v.into_iter()
            .map(|(r, d, u)| Sphere::new(u * d, r))
            .collect()
    })
}

/// How near a spawn point `p` a crossing of another sphere is too close to call, by
/// SPEC §3's rule (a bound from the floating-point error of the spawn point, no fixed
/// epsilon), written here rather than taken from the code under test: the point
/// `c + n·r` is off the exact one by a few units of roundoff `u` of its largest
/// coordinate (pbrt bounds a reprojected sphere point by γ₅·|p|, about 5u); the band
/// is 64u, so that only crossings the point's rounding could explain are left out.
fn spawn_doubt(p: DVec3) -> f64 {
    64.0 * (f64::EPSILON / 2.0) * p.abs().max_element()
}

/// The nearest crossing in front of the origin of each sphere, brute force in `f64`,
/// with a flag saying whether it is too close to call (tangent, or within `doubt` of
/// the origin: 0 for a primary ray, [`spawn_doubt`] for a spawned one).
fn crossings(
    o: DVec3,
    d: DVec3,
    spheres: &[Sphere],
    skip: Option<(usize, Side)>,
    doubt: f64,
) -> Vec<(usize, f64, DVec3, bool)> {
    let mut out = Vec::new();
    for (k, s) in spheres.iter().enumerate() {
        let own = skip.filter(|&(j, _)| j == k).map(|(_, side)| side);
        if own == Some(Side::Outward) {
            continue;
        }
        let f = s.center - o;
        let off = f.cross(d).length();
        let tangent = (off - s.radius).abs() <= 1e-7 * s.radius.max(f.length());
        let Some((near, far)) = roots64(o, d, s.center, s.radius) else {
            if tangent {
                out.push((k, f64::NAN, DVec3::ZERO, true));
            }
            continue;
        };
        let t = if own == Some(Side::Inward) {
            far
        } else if near > 0.0 {
            near
        } else {
            far
        };
        let end = t.abs() <= doubt || t == 0.0;
        if t > 0.0 || end {
            let n = (o + d * t - s.center) / s.radius;
            out.push((k, t, n, tangent || end));
        }
    }
    out
}

/// The spheres that brute force in `f64` sees clearly crossed by the primary ray from
/// `eye` in direction `d` (none too close to call).
fn clearly_crossed(eye: DVec3, d: Vec3, spheres: &[Sphere]) -> Vec<(usize, f64, DVec3, bool)> {
    let (o, d64) = query_ray(&Query {
        origin: eye,
        dir: d,
        from: None,
    });
    crossings(o, d64, spheres, None, 0.0)
        .into_iter()
        .filter(|x| !x.3)
        .collect()
}

/// What of a hit the shared queries must give as the per-ray one does.
fn hit_key(hit: Option<Hit>) -> Option<(u32, DVec3, DVec3, bool)> {
    hit.map(|h| (h.sphere, h.point, h.normal, h.entering))
}

/// The shadow ray from `hit` towards `light`, its length, and the shadow factor that
/// brute force in `f64` gives it (`None` when a crossing is too close to call: tangent,
/// or at an end of the segment).
fn shadow_case(spheres: &[Sphere], hit: &Hit, light: DVec3) -> (Query, f64, Option<f64>) {
    let to = light - hit.point;
    let dist = to.length();
    let sq = Query {
        origin: hit.point,
        dir: (to / dist).as_vec3().normalize(),
        from: Some((hit.sphere, Side::Outward)),
    };
    let (so, sd) = query_ray(&sq);
    let own = Some((hit.sphere as usize, Side::Outward));
    let occluders: Vec<_> = crossings(so, sd, spheres, own, spawn_doubt(so))
        .into_iter()
        .filter(|x| x.1.is_nan() || x.1 < dist * (1.0 + 1e-7))
        .collect();
    let doubtful = occluders
        .iter()
        .any(|x| x.3 || (x.1 - dist).abs() <= 1e-7 * dist);
    let factor = occluders
        .iter()
        .map(|x| (1.0 + sd.dot(x.2)) * 0.5)
        .fold(1.0f64, f64::min);
    (sq, dist, (!doubtful).then_some(factor))
}

#[derive(Default, Debug)]
struct Counts {
    rays: u64,
    hits: u64,
    ambiguous: u64,
    wrong: u64,
    shadow_rays: u64,
    shadowed: u64,
    shadow_ambiguous: u64,
    shadow_wrong: u64,
    /// Worlds whose light's grid lists spheres apart, seen wide, and the shadow rays
    /// tested in them.
    wide_worlds: u64,
    wide_shadow_rays: u64,
}

#[test]
fn culling_never_loses_a_hit_or_an_occluder() {
    let counts = RefCell::new(Counts::default());
    let rays = prop::collection::vec((unit_vector(), 0.0f64..1.0, 0.0f64..1.3), 24);
    runner(300)
        .run(
            &(
                world(),
                log_uniform(-1.0, 4.0),
                unit_vector(),
                unit_vector(),
                rays,
            ),
            |(spheres, eye_dist, eye_dir, light_dir, rays)| {
                let eye = eye_dir * eye_dist;
                let light = light_dir * (eye_dist * 3.0);
                let set = Spheres::new(&spheres).with_light_grids(&[light]);
                let eye_grid = set.eye_grid(eye, None);
                let mut c = counts.borrow_mut();
                let wide = set.lights[0].wide() > 0;
                c.wide_worlds += u64::from(wide);
                for &(u, pick, spread) in &rays {
                    // Aimed within 1.3 radii of a random sphere's centre: hits, misses
                    // and silhouettes alike.
                    let s =
                        &spheres[((pick * spheres.len() as f64) as usize).min(spheres.len() - 1)];
                    let dir = (s.center + u * (s.radius * spread) - eye).normalize_or(u);
                    let q = Query {
                        origin: eye,
                        dir: dir.as_vec3().normalize(),
                        from: None,
                    };
                    let (o, d) = query_ray(&q);
                    let all = crossings(o, d, &spheres, None, 0.0);
                    let mut sorted: Vec<_> = all.iter().filter(|x| !x.1.is_nan()).collect();
                    sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
                    c.rays += 1;
                    // Ambiguous: any doubtful crossing, or the two nearest nearly tied.
                    let tie = sorted.len() >= 2
                        && (sorted[1].1 - sorted[0].1) <= 1e-9 * sorted[1].1.abs();
                    if all.iter().any(|x| x.3) || tie {
                        c.ambiguous += 1;
                        continue;
                    }
                    let want = sorted.first().map(|x| x.0 as u32);
                    let pair = set.closest_from_eye_pair(&eye_grid, q.dir, -q.dir);
                    for (name, got) in [
                        ("closest", set.closest(&q)),
                        ("closest_primary", set.closest_primary(&eye_grid, &q)),
                        ("closest_from_eye", set.closest_from_eye(&eye_grid, q.dir)),
                        ("closest_from_eye_pair", pair[0]),
                    ] {
                        let got_k = got.map(|h| h.sphere);
                        if got_k != want {
                            c.wrong += 1;
                            prop_assert!(false, "{name}: sphere {got_k:?}, f64 says {want:?}");
                        }
                    }
                    // The eye's query with its precomputed constants is the general
                    // query, to the bit.
                    let key = |h: Option<Hit>| h.map(|h| (h.point, h.normal, h.entering));
                    prop_assert_eq!(
                        key(set.closest_primary(&eye_grid, &q)),
                        key(set.closest_from_eye(&eye_grid, q.dir))
                    );
                    // The pair's second ray, the other way, is the general query's too.
                    let back = Query { dir: -q.dir, ..q };
                    prop_assert_eq!(key(set.closest(&back)), key(pair[1]));
                    // The eye grid is no use to a ray from elsewhere: the primary query
                    // hands it to the general one.
                    let elsewhere = Query { origin: light, ..q };
                    prop_assert_eq!(
                        key(set.closest(&elsewhere)),
                        key(set.closest_primary(&eye_grid, &elsewhere))
                    );
                    // A shadow ray from the hit towards the light, through grid and BVH.
                    let Some(hit) = set.closest(&q) else { continue };
                    c.hits += 1;
                    let (sq, dist, want) = shadow_case(&spheres, &hit, light);
                    c.shadow_rays += 1;
                    c.wide_shadow_rays += u64::from(wide);
                    let Some(want) = want else {
                        c.shadow_ambiguous += 1;
                        continue;
                    };
                    c.shadowed += u64::from(want < 1.0);
                    let pair = set.shadow_to_light_pair((&sq, dist), (&sq, dist), 0);
                    for (name, got) in [
                        ("shadow", set.shadow(&sq, dist, light)),
                        ("shadow_to_light", set.shadow_to_light(&sq, dist, 0)),
                        ("shadow_to_light_pair, first", pair[0]),
                        ("shadow_to_light_pair, second", pair[1]),
                    ] {
                        if (f64::from(got) - want).abs() > 1e-5 {
                            c.shadow_wrong += 1;
                            prop_assert!(false, "{name}: factor {got}, f64 says {want}");
                        }
                    }
                }
                Ok(())
            },
        )
        .unwrap_or_else(|e| panic!("{e}\n{:?}", counts.borrow()));
    let c = counts.into_inner();
    println!(
        "culling: {} primary rays ({} ambiguous, left out; {} hits), {} wrong; {} shadow rays ({} ambiguous, {} shadowed), {} wrong; {} worlds with wide spheres apart, {} shadow rays in them",
        c.rays, c.ambiguous, c.hits, c.wrong, c.shadow_rays, c.shadow_ambiguous, c.shadowed, c.shadow_wrong, c.wide_worlds, c.wide_shadow_rays
    );
    assert!(
        c.rays - c.ambiguous > 5000
            && c.shadow_rays - c.shadow_ambiguous > 1000
            && c.wide_shadow_rays > 200,
        "{c:?}"
    );
}

/// A camera's eye grid leaves out the spheres outside its view, and loses none that a
/// primary ray meets: through every part of the film (its corners and edges too, the
/// directions rounded as the tracer rounds them), the grid of the camera's view gives
/// the same hits, to the bit, as the grid of every sphere (itself checked against brute
/// force above).
#[test]
fn a_camera_s_eye_grid_keeps_every_sphere_its_film_sees() {
    use crate::accel::ViewPyramid;
    use crate::camera::{Camera, CameraSpec};
    // (rays, hits, spheres left out, spheres kept)
    let counts = RefCell::new((0u64, 0u64, 0usize, 0usize));
    let film = prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0u8..4), 48);
    runner(200)
        .run(
            &(
                world(),
                log_uniform(-1.0, 4.0),
                unit_vector(),
                unit_vector(),
                10.0f64..170.0,
                (1u32..2000, 1u32..2000),
                film,
            ),
            |(mut spheres, eye_dist, eye_dir, look, vfov, (width, height), film)| {
                let eye = eye_dir * eye_dist;
                let spec = CameraSpec::LookAt {
                    look_from: eye,
                    look_at: eye + look,
                    up: if look.y.abs() < 0.9 {
                        DVec3::Y
                    } else {
                        DVec3::X
                    },
                    vfov,
                };
                let camera = Camera::new(&spec, width, height).expect("a valid camera");
                let view = ViewPyramid::new(
                    camera.origin,
                    camera.lower_left,
                    camera.horizontal,
                    camera.vertical,
                )
                .expect("a look-at camera makes a pyramid");
                // Four spheres centred just outside the film's four edges, each
                // reaching 1e-4 of the film in (its silhouette touches the direction
                // through that point), and the edge rays that meet them: a grid that
                // trims its view by more than that loses them.
                let film_dir = |s: f64, t: f64| {
                    camera.lower_left + s * camera.horizontal + t * camera.vertical - eye
                };
                let mut edge_rays = Vec::new();
                for (side, &(a, b, _)) in film.iter().take(4).enumerate() {
                    const OUT: f64 = 0.005;
                    const IN: f64 = 1e-4;
                    let (centre, reach, edge) = match side {
                        0 => ((-OUT, b), (IN, b), (0.0, b)),
                        1 => ((1.0 + OUT, b), (1.0 - IN, b), (1.0, b)),
                        2 => ((a, -OUT), (a, IN), (a, 0.0)),
                        _ => ((a, 1.0 + OUT), (a, 1.0 - IN), (a, 1.0)),
                    };
                    let towards = film_dir(centre.0, centre.1).normalize();
                    let dist = 1.0 + 5.0 * a;
                    // The sine of the angle to the reach direction, times the distance.
                    let r = dist
                        * towards
                            .cross(film_dir(reach.0, reach.1).normalize())
                            .length();
                    spheres.push(Sphere::new(eye + towards * dist, r));
                    edge_rays.push(edge);
                }
                let set = Spheres::new(&spheres);
                let all = set.eye_grid(eye, None);
                let seen = set.eye_grid(eye, Some(&view));
                let outside = spheres
                    .iter()
                    .filter(|s| !view.may_see(s.center - eye, s.radius))
                    .count();
                let mut c = counts.borrow_mut();
                c.2 += outside;
                c.3 += spheres.len() - outside;
                let corner = (camera.lower_left - camera.origin).as_vec3();
                let (h, v) = (camera.horizontal.as_vec3(), camera.vertical.as_vec3());
                // Film coordinates on an edge or at a corner three times in four.
                let on_film = film.iter().map(|&(a, b, edge)| match edge {
                    0 => (a, b),
                    1 => (a.round(), b),
                    2 => (a, b.round()),
                    _ => (a.round(), b.round()),
                });
                for (s, t) in on_film.chain(edge_rays) {
                    let dir = crate::model::primary_direction(corner, h, v, s as f32, t as f32);
                    let q = Query {
                        origin: eye,
                        dir,
                        from: None,
                    };
                    let key = |hit: Option<Hit>| hit.map(|h| (h.sphere, h.point, h.normal));
                    let want = key(set.closest_primary(&all, &q));
                    prop_assert_eq!(key(set.closest_primary(&seen, &q)), want);
                    prop_assert_eq!(
                        key(set.closest_from_eye(&seen, dir)),
                        key(set.closest_from_eye(&all, dir))
                    );
                    c.0 += 1;
                    c.1 += u64::from(want.is_some());
                }
                Ok(())
            },
        )
        .unwrap();
    let (rays, hits, left_out, kept) = counts.into_inner();
    println!("view grids: {rays} rays ({hits} hits); {left_out} spheres left out, {kept} kept");
    assert!(
        hits > 500 && left_out > 5000 && kept > 5000,
        "{hits} {left_out} {kept}"
    );
}

/// The tracer's sky runs: when `eye_sees_nothing_between` says a row of directions sees
/// only sky, every direction between (as a row of pixels computes them) misses every
/// sphere, by brute force in `f64`, and the eye query agrees. Rows from a thousandth of
/// a radian (within a cell) to 0.4 (across several cells, and faces).
#[test]
fn sky_runs_see_no_sphere() {
    // (runs said empty, of them across cells, directions checked)
    let counts = RefCell::new((0u64, 0u64, 0u64));
    let runs = prop::collection::vec((unit_vector(), unit_vector(), log_uniform(-3.0, -0.4)), 32);
    runner(200)
        .run(
            &(world(), log_uniform(-1.0, 4.0), unit_vector(), runs),
            |(spheres, eye_dist, eye_dir, runs)| {
                // Few spheres, so that empty cells are common.
                let spheres = &spheres[..spheres.len().min(12)];
                let eye = eye_dir * eye_dist;
                let set = Spheres::new(spheres);
                let grid = set.eye_grid(eye, None);
                let mut c = counts.borrow_mut();
                for &(base, across, span) in &runs {
                    // A row: corner + s·h with s in [0, 1], as the camera forms it.
                    let h = across.cross(base).normalize_or(across) * span;
                    let (corner, h) = (base.as_vec3(), h.as_vec3());
                    let dir = |s: f32| (corner + h * s).normalize();
                    if !set.eye_sees_nothing_between(&grid, dir(0.0), dir(1.0)) {
                        continue;
                    }
                    c.0 += 1;
                    let cells = grid
                        .shortcut(spheres.len())
                        .map(|g| g.cell(dir(0.0)) != g.cell(dir(1.0)));
                    c.1 += u64::from(cells == Some(true));
                    for step in 0..=16 {
                        let d = dir(step as f32 / 16.0);
                        c.2 += 1;
                        let hits = clearly_crossed(eye, d, spheres);
                        prop_assert!(hits.is_empty(), "a sky run hits {hits:?}");
                        prop_assert!(set.closest_from_eye(&grid, d).is_none());
                    }
                }
                Ok(())
            },
        )
        .unwrap_or_else(|e| panic!("{e}\n{:?}", counts.borrow()));
    let (empty, across, checked) = counts.into_inner();
    println!("sky runs: {empty} said empty ({across} across cells), {checked} directions checked");
    assert!(
        empty > 500 && across > 200,
        "too few empty runs to say anything: {empty}, {across} across cells"
    );
}

/// The tracer's shared cells: when `eye_run` says a row of directions lies in one cell
/// of the eye grid, the query of each direction with that cell's spheres gives the
/// per-ray query's hit to the bit (which `culling_never_loses_a_hit_or_an_occluder` checks
/// against brute force).
#[test]
fn rows_in_one_cell_get_the_per_ray_hits() {
    let counts = RefCell::new((0u64, 0u64, 0u64)); // (runs in one cell, directions, hits)
    let runs = prop::collection::vec((0.0f64..1.0, unit_vector(), 0.0f64..0.02), 24);
    runner(150)
        .run(
            &(world(), log_uniform(-1.0, 4.0), unit_vector(), runs),
            |(spheres, eye_dist, eye_dir, runs)| {
                let eye = eye_dir * eye_dist;
                let set = Spheres::new(&spheres);
                let grid = set.eye_grid(eye, None);
                let mut c = counts.borrow_mut();
                for &(pick, across, span) in &runs {
                    // A row through a random sphere, as the camera forms it.
                    let s =
                        &spheres[((pick * spheres.len() as f64) as usize).min(spheres.len() - 1)];
                    let base = (s.center - eye).normalize_or(across);
                    let h = across.cross(base).normalize_or(across) * span;
                    let (corner, h) = ((base - h * 0.5).as_vec3(), h.as_vec3());
                    let dir = |s: f32| (corner + h * s).normalize();
                    let Some(run) = set.eye_run(&grid, [dir(0.0), dir(1.0)]) else {
                        continue;
                    };
                    c.0 += 1;
                    for step in 0..=8 {
                        let (a, b) = (dir(step as f32 / 8.0), dir(1.0 - step as f32 / 8.0));
                        c.1 += 2;
                        let shared = set.closest_in_run_pair(&grid, &run, a, b);
                        for (d, got) in [(a, shared[0]), (b, shared[1])] {
                            let alone = set.closest_from_eye(&grid, d);
                            prop_assert_eq!(hit_key(got), hit_key(alone));
                            c.2 += u64::from(got.is_some());
                            prop_assert!(!run.sees_nothing() || got.is_none());
                        }
                    }
                }
                Ok(())
            },
        )
        .unwrap_or_else(|e| panic!("{e}\n{:?}", counts.borrow()));
    let (runs, checked, hits) = counts.into_inner();
    println!("rows in one cell: {runs} runs, {checked} directions, {hits} hits");
    assert!(
        runs > 500 && hits > 2000,
        "too few to say anything: {runs} runs, {hits} hits"
    );
}

/// The tracer's pixel squares: when `eye_area` says the directions through a
/// parallelogram of the film (corner + s·h + t·v, s and t in [0, 1], its corners given
/// unnormalised, as the tracer gives a pixel's) fall in one cell, the query of each
/// direction with that cell's spheres gives the per-ray query's hit to the bit; when it
/// says they see the sky, brute force in `f64` finds no sphere along any of them.
#[test]
fn pixel_squares_in_one_cell_or_the_sky_get_the_per_ray_hits() {
    // (squares in one cell, squares of sky, directions checked, hits, squares whose
    // last corner alone leaves the others' cell)
    let counts = RefCell::new((0u64, 0u64, 0u64, 0u64, 0u64));
    let squares = prop::collection::vec(
        (
            0.0f64..1.0,
            unit_vector(),
            log_uniform(-4.0, -1.5),
            0.3f64..3.0,
        ),
        24,
    );
    runner(150)
        .run(
            &(
                world(),
                any::<bool>(),
                log_uniform(-1.0, 4.0),
                unit_vector(),
                squares,
            ),
            |(spheres, few, eye_dist, eye_dir, squares)| {
                // Few spheres in half the worlds, so that empty cells are common.
                let spheres = &spheres[..spheres.len().min(if few { 12 } else { usize::MAX })];
                let eye = eye_dir * eye_dist;
                let set = Spheres::new(spheres);
                let grid = set.eye_grid(eye, None);
                let mut c = counts.borrow_mut();
                for &(pick, across, span, aspect) in &squares {
                    // A square through a random sphere, or (a third of them) towards
                    // anywhere, tilted at random.
                    let s =
                        &spheres[((pick * spheres.len() as f64) as usize).min(spheres.len() - 1)];
                    let base = if pick < 0.33 {
                        across.any_orthonormal_vector()
                    } else {
                        (s.center - eye).normalize_or(across)
                    };
                    let h = across.cross(base).normalize_or(across) * span;
                    let v = base.cross(h).normalize_or(across) * (span * aspect);
                    let (corner, h, v) =
                        ((base - (h + v) * 0.5).as_vec3(), h.as_vec3(), v.as_vec3());
                    let toward = |s: f32, t: f32| (corner + h * s) + v * t;
                    let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
                    // One cell exactly when all four corners fall in it (this square
                    // and larger ones about it).
                    if let Some(g) = grid.shortcut(spheres.len()) {
                        for grow in [1.0, 3.0, 9.0, 27.0, 81.0] {
                            let centre = corner + (h + v) * 0.5;
                            let at =
                                |s: f32, t: f32| centre + (h * (s - 0.5) + v * (t - 0.5)) * grow;
                            let ends = corners.map(|(s, t)| at(s, t));
                            let places = ends.map(|d| g.place(d));
                            let one_cell = places.iter().all(|&p| p == places[0]);
                            let cell = Some(EyeArea::Cell(g.cell_at(places[0]) as u32));
                            prop_assert_eq!(one_cell, set.eye_area(&grid, ends) == cell);
                            let last_out = places[..3].iter().all(|&p| p == places[0]);
                            c.4 += u64::from(!one_cell && last_out);
                        }
                    }
                    let area = set.eye_area(&grid, corners.map(|(s, t)| toward(s, t)));
                    let Some(area) = area else {
                        continue;
                    };
                    let run = grid.run(area);
                    if run.sees_nothing() {
                        c.1 += 1;
                    } else {
                        c.0 += 1;
                    }
                    // A 7 × 7 lattice over the square, its edges and corners included.
                    for step in 0..49 {
                        let (s, t) = ((step % 7) as f32 / 6.0, (step / 7) as f32 / 6.0);
                        let (a, b) = (toward(s, t).normalize(), toward(1.0 - s, t).normalize());
                        c.2 += 2;
                        let shared = set.closest_in_run_pair(&grid, &run, a, b);
                        for (d, got) in [(a, shared[0]), (b, shared[1])] {
                            let alone = set.closest_from_eye(&grid, d);
                            prop_assert_eq!(hit_key(got), hit_key(alone));
                            c.3 += u64::from(got.is_some());
                            if run.sees_nothing() {
                                let hits = clearly_crossed(eye, d, spheres);
                                prop_assert!(hits.is_empty(), "a square of sky hits {hits:?}");
                            }
                        }
                    }
                }
                Ok(())
            },
        )
        .unwrap_or_else(|e| panic!("{e}\n{:?}", counts.borrow()));
    let (cells, sky, checked, hits, last_out) = counts.into_inner();
    println!(
        "pixel squares: {cells} in one cell, {sky} of sky, {checked} directions, {hits} hits, \
         {last_out} left by the last corner alone"
    );
    assert!(
        cells > 500 && sky > 100 && hits > 2000 && last_out > 20,
        "too few to say anything: {cells} in one cell, {sky} of sky, {hits} hits, \
         {last_out} left by the last corner alone"
    );
}

/// Rays going into a sphere (refracted into glass): the query takes only that sphere
/// and the spheres overlapping it, and must find what brute force in `f64` finds among
/// all spheres — the far side, or an overlapping sphere crossed before it.
#[test]
fn rays_inside_a_sphere_meet_what_brute_force_meets() {
    // (rays, ambiguous, met another sphere)
    let counts = RefCell::new((0u64, 0u64, 0u64));
    // Spheres in overlapping pairs, triples and quadruples, at every scale.
    let cluster = (
        log_uniform(-3.0, 3.0),
        log_uniform(-1.0, 4.0),
        unit_vector(),
        prop::collection::vec((unit_vector(), 0.2f64..1.6, 0.2f64..1.2), 0..3),
    );
    let world = prop::collection::vec(cluster, 1..40).prop_map(|clusters| {
        let mut spheres = Vec::new();
        for (r, d, u, others) in clusters {
            let c = u * d;
            spheres.push(Sphere::new(c, r));
            // And one that overlaps it by a hair: 10⁻⁷ of the two radii.
            let v = u.any_orthonormal_vector();
            spheres.push(Sphere::new(c + v * (1.5 * r * (1.0 - 1e-7)), 0.5 * r));
            for (v, off, size) in others {
                spheres.push(Sphere::new(c + v * (r * off), r * size));
            }
        }
        spheres
    });
    let rays = prop::collection::vec((0.0f64..1.0, unit_vector(), unit_vector()), 48);
    runner(150)
        .run(&(world, rays), |(spheres, rays)| {
            // Both ways of answering a ray inside a sphere: the lists of overlapping
            // spheres, and the hierarchy's walk up to the far side (what scenes of
            // many spheres use for their small ones).
            let with_lists = Spheres::new(&spheres);
            let mut walking = Spheres::new(&spheres);
            walking.inside = InsideLists {
                keepers: Some(Vec::new()),
                lists: Vec::new(),
            };
            // A sphere's list holds the spheres that overlap or touch it, and no
            // other (by a margin of 10⁻⁵ of the two radii).
            for (s, sphere) in spheres.iter().enumerate() {
                let list = with_lists
                    .overlapping(s as u32, usize::MAX)
                    .expect("no bound");
                for (k, other) in spheres.iter().enumerate() {
                    let sum = sphere.radius + other.radius;
                    let gap = (other.center - sphere.center).length() - sum;
                    let far = sphere.center.abs().max_element() + other.center.abs().max_element();
                    let listed = list.contains(&(k as u32));
                    if k == s || gap > 1e-5 * sum + 1e-8 * far {
                        prop_assert!(!listed, "sphere {k} in the list of {s}, {gap:e} apart");
                    } else if gap < 0.0 {
                        prop_assert!(listed, "sphere {k} not in the list of {s}, {gap:e} apart");
                    }
                }
            }
            let mut c = counts.borrow_mut();
            for &(pick, n, towards) in &rays {
                let s = ((pick * spheres.len() as f64) as usize).min(spheres.len() - 1);
                let sphere = &spheres[s];
                // A point on the sphere and a direction into it.
                let origin = sphere.center + n * sphere.radius;
                let inward = if towards.dot(n) < 0.0 {
                    towards
                } else {
                    -towards
                };
                let q = Query {
                    origin,
                    dir: inward.as_vec3().normalize(),
                    from: Some((s as u32, Side::Inward)),
                };
                let (o, d) = query_ray(&q);
                let mut all: Vec<_> =
                    crossings(o, d, &spheres, Some((s, Side::Inward)), spawn_doubt(o))
                        .into_iter()
                        .collect();
                all.sort_by(|a, b| a.1.total_cmp(&b.1));
                c.0 += 1;
                let tie = all.len() >= 2 && (all[1].1 - all[0].1) <= 1e-9 * all[1].1.abs();
                let grazing = inward.dot(n).abs() < 1e-3;
                if all.iter().any(|x| x.3 || x.1.is_nan()) || tie || grazing {
                    c.1 += 1;
                    continue;
                }
                let want = all.first().map(|x| x.0 as u32);
                let listed = with_lists.closest(&q);
                let walked = walking.closest(&q);
                c.2 += u64::from(want.is_some_and(|k| k != s as u32));
                prop_assert_eq!(
                    listed.map(|h| h.sphere),
                    want,
                    "sphere {} of {}",
                    s,
                    spheres.len()
                );
                // The same hit to the bit.
                let key = |h: Option<Hit>| h.map(|h| (h.sphere, h.point, h.normal, h.entering));
                prop_assert_eq!(key(walked), key(listed));
            }
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{e}\n{:?}", counts.borrow()));
    let (rays, ambiguous, other) = counts.into_inner();
    println!("inside rays: {rays} ({ambiguous} ambiguous, left out), {other} met an overlapping sphere first");
    assert!(
        rays - ambiguous > 4000 && other > 300,
        "too few to say anything: {rays} {ambiguous} {other}"
    );
}

/// The sphere query `q` meets first (`Some(None)`: none, the sky), by brute force
/// in `f64`; `None` when that is too close to call (a tangent crossing, or two nearest
/// crossings within 10⁻⁹ of each other).
fn nearest_sphere(q: &Query, spheres: &[Sphere]) -> Option<Option<u32>> {
    let (o, d) = query_ray(q);
    let all = crossings(o, d, spheres, None, 0.0);
    let mut sorted: Vec<_> = all.iter().filter(|x| !x.1.is_nan()).collect();
    sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
    let tie = sorted.len() >= 2 && (sorted[1].1 - sorted[0].1) <= 1e-9 * sorted[1].1.abs();
    (!(all.iter().any(|x| x.3) || tie)).then(|| sorted.first().map(|x| x.0 as u32))
}

/// Uniform numbers in [0, 1) from a xorshift generator seeded with `state`.
fn xorshift(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A point within 1.3 radii of a sphere's centre, the sphere drawn at random.
fn aim_near_a_ball(next: &mut impl FnMut() -> f64, spheres: &[Sphere]) -> DVec3 {
    let s = &spheres[((next() * spheres.len() as f64) as usize).min(spheres.len() - 1)];
    let u = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
    s.center + u * (2.6 * s.radius)
}

/// Fine grids (the eye's 128 cells a face for 4,097 to 65,536 spheres, the lights'
/// finest, 256) and a hierarchy whose big subtrees are built on threads of their own: the
/// peers' scene of 20,000 balls on the ground, seen from its camera. Every primary
/// ray's sphere, the shadow factor from its hit, and the sphere a ray from a point
/// among the balls meets through the hierarchy, equal brute force in `f64`
/// (ambiguous cases left out and counted, as above).
#[test]
fn large_scenes_lose_no_hit_or_occluder() {
    let scene = crate::scene::many_scene(20_000);
    let spheres = &scene.spheres;
    let light = scene.lights[0].position;
    let eye = DVec3::new(0.0, 18.0, 60.0);
    let set = Spheres::new(spheres).with_light_grids(&[light]);
    let eye_grid = set.eye_grid(eye, None);
    // A fixed sequence of rays, each aimed within 1.3 radii of a sphere's centre.
    let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
    let (mut tested, mut ambiguous, mut shadows) = (0u32, 0u32, 0u32);
    let (mut balls, mut shadowed) = (0u32, 0u32);
    let (mut walks, mut walks_on_balls) = (0u32, 0u32);
    for _ in 0..3000 {
        let aim = aim_near_a_ball(&mut next, spheres);
        let q = Query {
            origin: eye,
            dir: (aim - eye).normalize().as_vec3().normalize(),
            from: None,
        };
        let Some(want) = nearest_sphere(&q, spheres) else {
            ambiguous += 1;
            continue;
        };
        tested += 1;
        let got = set.closest_from_eye(&eye_grid, q.dir);
        assert_eq!(got.map(|h| h.sphere), want, "ray {q:?}");
        // The same aim from a point among the balls, through the hierarchy.
        let from = DVec3::new(next() - 0.5, 0.1 * next(), next() - 0.5) * 40.0;
        let walked = Query {
            origin: from,
            dir: (aim - from).normalize().as_vec3().normalize(),
            from: None,
        };
        if let Some(want) = nearest_sphere(&walked, spheres) {
            walks += 1;
            walks_on_balls += u32::from(want.is_some_and(|k| k >= 4));
            let got = set.closest(&walked).map(|h| h.sphere);
            assert_eq!(got, want, "walk {walked:?}");
        }
        let Some(hit) = got else { continue };
        balls += u32::from(hit.sphere >= 4); // not the ground nor the three big balls
        let (sq, dist, want) = shadow_case(spheres, &hit, light);
        let Some(want) = want else { continue };
        shadows += 1;
        shadowed += u32::from(want < 1.0);
        let got = set.shadow_to_light(&sq, dist, 0);
        assert!(
            (f64::from(got) - want).abs() <= 1e-5,
            "shadow {got}, f64 says {want}"
        );
    }
    println!(
        "large scene: {tested} primary rays tested ({ambiguous} ambiguous, {balls} on small \
         balls), {shadows} shadow rays ({shadowed} shadowed), {walks} walks \
         ({walks_on_balls} on small balls)"
    );
    assert!(
        walks > 2500 && walks_on_balls > 1000,
        "{walks} {walks_on_balls}"
    );
    assert!(tested > 2500 && balls > 1000, "{tested} {balls}");
    assert!(shadows > 1500 && shadowed > 100, "{shadows} {shadowed}");
}

/// Above 2^18 spheres the hierarchy comes from the Morton order: in the peers' scene
/// of 300,000 balls on the ground, the sphere a ray from a point among the balls
/// meets through the hierarchy equals brute force in `f64` (ambiguous cases left
/// out).
#[test]
fn a_hierarchy_from_the_morton_order_loses_no_hit() {
    const _: () = assert!(300_000 > crate::accel::bvh::MORTON_ABOVE);
    let scene = crate::scene::many_scene(300_000);
    let spheres = &scene.spheres;
    let set = Spheres::new(spheres);
    let mut next = xorshift(0x2545_f491_4f6c_dd1d);
    let (mut walks, mut on_balls) = (0u32, 0u32);
    for _ in 0..400 {
        let aim = aim_near_a_ball(&mut next, spheres);
        let from = DVec3::new(next() - 0.5, 0.1 * next(), next() - 0.5) * 100.0;
        let q = Query {
            origin: from,
            dir: (aim - from).normalize().as_vec3().normalize(),
            from: None,
        };
        let Some(want) = nearest_sphere(&q, spheres) else {
            continue;
        };
        walks += 1;
        on_balls += u32::from(want.is_some_and(|k| k >= 4));
        assert_eq!(set.closest(&q).map(|h| h.sphere), want, "walk {q:?}");
    }
    println!("{walks} walks ({on_balls} on small balls)");
    assert!(walks > 350 && on_balls > 200, "{walks} {on_balls}");
}

/// The lights' grids share one grid's bound: over 20,000 small balls one light gets
/// its grid at the finest resolution, each of 64 lights a coarser one, and 1,024
/// lights none (their shadow rays walk the hierarchy); every shadow factor, from
/// either, equals brute force.
#[test]
fn many_lights_share_one_grid_s_bound_and_lose_no_occluder() {
    let scene = crate::scene::many_scene(20_000);
    let spheres = &scene.spheres;
    let ring = |count: usize| -> Vec<DVec3> {
        (0..count)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / count as f64;
                DVec3::new(60.0 * a.cos(), 40.0 + 20.0 * (i % 5) as f64, 60.0 * a.sin())
            })
            .collect()
    };
    let bound = super::super::dirgrid::most_entries(spheres.len());
    let one = Spheres::new(spheres).with_light_grids(&ring(1));
    assert_eq!(one.lights[0].size().map(|s| s.0), Some(256));
    let some = Spheres::new(spheres).with_light_grids(&ring(64));
    let sizes: Vec<(u32, usize)> = some.lights.iter().filter_map(|l| l.size()).collect();
    assert_eq!(sizes.len(), 64, "every light keeps a grid");
    assert!(sizes.iter().all(|&(n, _)| n < 256), "{sizes:?}");
    assert!(sizes.iter().map(|s| s.1).sum::<usize>() <= bound);
    let many = Spheres::new(spheres).with_light_grids(&ring(1024));
    assert!(many.lights.iter().all(|l| !l.has_grid()));

    let eye = DVec3::new(0.0, 18.0, 60.0);
    let eye_grid = one.eye_grid(eye, None);
    let (mut shadows, mut shadowed) = (0, 0);
    for (i, dir) in even_directions(4000).into_iter().enumerate() {
        let dir = dir.as_vec3().normalize();
        let Some(hit) = one.closest_from_eye(&eye_grid, dir) else {
            continue;
        };
        for (set, light) in [(&some, i % 64), (&many, i % 1024)] {
            let position = set.lights[light].centre();
            let (sq, dist, Some(want)) = shadow_case(spheres, &hit, position) else {
                continue;
            };
            shadows += 1;
            shadowed += u32::from(want < 1.0);
            let got = set.shadow_to_light(&sq, dist, light);
            assert!(
                (f64::from(got) - want).abs() <= 1e-5,
                "ray {i}, light {light}: shadow {got}, f64 says {want}"
            );
        }
    }
    println!(
        "many lights: 64 grids of {:?} (cells a side, room), {shadows} shadow rays \
         ({shadowed} shadowed)",
        sizes[0]
    );
    assert!(shadows > 1000 && shadowed > 50, "{shadows} {shadowed}");
}

/// Balls crowding the eye and the light, each seen over a seventh of the sky from
/// both, would fill even their coarsest grids past the bound: the build gives them
/// none, and the eye's and the light's queries walk the hierarchy instead, losing
/// nothing against brute force.
#[test]
fn a_crowded_eye_and_light_walk_the_hierarchy_and_lose_nothing() {
    // With small balls in the hollow, which cast shadows on the crowd.
    let spheres: Vec<Sphere> = even_directions(8000)
        .into_iter()
        .enumerate()
        .map(|(k, d)| Sphere::new(d * (1.3 + 0.03 * (k * 7 % 11) as f64), 1.0))
        .chain(
            even_directions(40)
                .into_iter()
                .map(|d| Sphere::new(d * 0.2, 0.03)),
        )
        .collect();
    let (eye, light) = (DVec3::ZERO, DVec3::new(0.1, 0.05, -0.05));
    let (set, eye_grid) = Spheres::build_for_view(&spheres, &[light], eye, None);
    assert!(!eye_grid.has_grid(), "the eye's grid would pass its bound");
    assert!(
        !set.lights[0].has_grid(),
        "the light's grid would pass its bound"
    );
    let (mut checked, mut shadows, mut shadowed) = (0, 0, 0);
    for (i, dir) in even_directions(1500).into_iter().enumerate() {
        let dir = dir.as_vec3().normalize();
        let q = Query {
            origin: eye,
            dir,
            from: None,
        };
        assert!(set.eye_run(&eye_grid, [dir, dir]).is_none());
        let (o, d) = query_ray(&q);
        let all = crossings(o, d, &spheres, None, 0.0);
        let mut sorted: Vec<_> = all.iter().filter(|x| !x.1.is_nan()).collect();
        sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
        let tie = sorted.len() >= 2 && (sorted[1].1 - sorted[0].1) <= 1e-9 * sorted[1].1;
        if all.iter().any(|x| x.3) || tie {
            continue;
        }
        checked += 1;
        let want = sorted.first().map(|x| x.0 as u32);
        let pair = set.closest_from_eye_pair(&eye_grid, dir, dir);
        for (name, got) in [
            ("closest_primary", set.closest_primary(&eye_grid, &q)),
            ("closest_from_eye", set.closest_from_eye(&eye_grid, dir)),
            ("closest_from_eye_pair, first", pair[0]),
            ("closest_from_eye_pair, second", pair[1]),
        ] {
            assert_eq!(got.map(|h| h.sphere), want, "{name}, ray {i}");
        }
        let Some(hit) = set.closest(&q) else { continue };
        let (sq, dist, Some(want)) = shadow_case(&spheres, &hit, light) else {
            continue;
        };
        shadows += 1;
        shadowed += u32::from(want < 1.0);
        let pair = set.shadow_to_light_pair((&sq, dist), (&sq, dist), 0);
        for (name, got) in [
            ("shadow_to_light", set.shadow_to_light(&sq, dist, 0)),
            ("shadow_to_light_pair, first", pair[0]),
            ("shadow_to_light_pair, second", pair[1]),
        ] {
            assert!(
                (f64::from(got) - want).abs() <= 1e-5,
                "{name}, ray {i}: factor {got}, f64 says {want}"
            );
        }
    }
    println!(
        "crowded: {checked} primary rays checked, {shadows} shadow rays ({shadowed} shadowed)"
    );
    assert!(checked > 1000 && shadows > 500 && shadowed > 100);
}
