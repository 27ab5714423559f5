//! The work the culling exists to skip, on scenes built by hand where the exact tests
//! a query needs are known: a sphere the ray cannot meet, or the one it leaves, costs
//! no exact test; the quick tests, the overlap lists and the view pyramid keep no more
//! than their rounding allowances; the structures a tracer builds are the ones its
//! shortcuts read. Pixels cannot show any of this (a looser cull gives the same image,
//! slower), so these tests are what holds it.

use std::sync::OnceLock;

use glam::DVec3;
use proptest::prop_assert;

use super::{log_uniform, query, runner, unit_vector};
use crate::accel::dirgrid::{DirGrid, Listed};
use crate::accel::view::ViewPyramid;
use crate::accel::{exact_tests, eye_resolution, grid_resolution, may_cross, Ray, Spheres};
use crate::model::Side;
use crate::scene::Sphere;

/// Ball 0 at the origin, ball 1 ahead of it along +x, and three that no ray along the
/// x axis meets: one beside it, one behind, one far off.
fn row_of_balls() -> Vec<Sphere> {
    vec![
        Sphere::new(DVec3::ZERO, 1.0),
        Sphere::new(DVec3::new(5.0, 0.0, 0.0), 1.0),
        Sphere::new(DVec3::new(5.0, 4.0, 0.0), 1.0),
        Sphere::new(DVec3::new(-5.0, 0.0, 0.0), 1.0),
        Sphere::new(DVec3::new(3.0, -50.0, 20.0), 2.0),
    ]
}

/// A ray leaving ball 0 along +x: only ball 1 is tested exactly. Ball 0 is the one it
/// leaves (no crossing ahead of it), and the quick test rejects the others.
#[test]
fn a_ray_leaving_a_ball_tests_only_the_ball_ahead() {
    let set = Spheres::new(&row_of_balls());
    let q = query(
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::X,
        Some((0, Side::Outward)),
    );
    let (tests, hit) = exact_tests(|| set.closest(&q));
    let hit = hit.expect("ball 1 is ahead");
    assert_eq!((hit.sphere, hit.point), (1, DVec3::new(4.0, 0.0, 0.0)));
    assert_eq!(tests, 1);
}

/// A ray going into a big ball that overlaps a small one off its path: the ball's far
/// side is the one exact test; the overlapping ball is on the ball's list, and its
/// quick test rejects it.
#[test]
fn a_ray_inside_a_ball_tests_only_its_far_side() {
    let set = Spheres::new(&[
        Sphere::new(DVec3::ZERO, 10.0),
        Sphere::new(DVec3::new(0.0, 9.0, 0.0), 2.0),
    ]);
    let q = query(
        DVec3::new(-10.0, 0.0, 0.0),
        DVec3::X,
        Some((0, Side::Inward)),
    );
    let (tests, hit) = exact_tests(|| set.closest_inside(0, &q));
    let hit = hit.expect("the far side of the ball the ray is in");
    assert_eq!(
        (hit.sphere, hit.point, hit.entering),
        (0, DVec3::new(10.0, 0.0, 0.0), false)
    );
    assert_eq!(tests, 1);
    assert_eq!(
        set.inside
            .of(0)
            .and_then(OnceLock::get)
            .map(|list| list.as_deref()),
        Some(Some(&[1][..])),
        "a ball of a small scene keeps its list of overlapping balls"
    );
}

/// A ball overlapped by 16 others keeps their list; by 17, none, and a ray inside it
/// walks the hierarchy: the same hit either way (the small ball inside, on its path).
#[test]
fn a_ball_overlapped_by_many_keeps_no_list() {
    for (ring, listed) in [(15, true), (16, false)] {
        // Ball 0, ball 1 inside it on the x axis, and `ring` balls on its surface
        // around the x axis, off the ray's path.
        let mut spheres = vec![
            Sphere::new(DVec3::ZERO, 10.0),
            Sphere::new(DVec3::new(5.0, 0.0, 0.0), 0.5),
        ];
        spheres.extend((0..ring).map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(ring);
            Sphere::new(DVec3::new(0.0, a.cos(), a.sin()) * 10.0, 0.5)
        }));
        let set = Spheres::new(&spheres);
        let q = query(
            DVec3::new(-10.0, 0.0, 0.0),
            DVec3::X,
            Some((0, Side::Inward)),
        );
        let hit = set.closest(&q).expect("ball 1 ahead");
        assert_eq!((hit.sphere, hit.point), (1, DVec3::new(4.5, 0.0, 0.0)));
        let list = set
            .inside
            .of(0)
            .and_then(OnceLock::get)
            .expect("worked out")
            .as_deref();
        assert_eq!(list.map(<[u32]>::len), listed.then_some(ring as usize + 1));
    }
}

/// A shadow query from the top of ball 0 to a light inside it, leaving ball 0 by its
/// outer side: a ray leaving a sphere's outside cannot cross it again, so ball 0 costs
/// no exact test, although it holds the light (it is in the grid's `always` list,
/// whose spheres the quick test cannot reject: the segment ends inside them); the
/// other balls are off the segment.
#[test]
fn a_shadow_ray_tests_no_ball_it_cannot_cross() {
    let light = DVec3::new(0.0, 0.5, 0.0);
    let set = Spheres::new(&row_of_balls()).with_light_grids(&[light]);
    let q = query(DVec3::Y, -DVec3::Y, Some((0, Side::Outward)));
    let (tests, factor) = exact_tests(|| set.shadow_to_light(&q, 0.5, 0));
    assert_eq!((tests, factor), (0, 1.0));
}

/// A shadow query from the top of ball 0 to a light above it: ball 0 is in the
/// light's cell (the light sees it there), but the segment leaves its outer side, so
/// it costs no exact test.
#[test]
fn a_shadow_ray_skips_the_ball_it_leaves_among_the_light_s_candidates() {
    let light = DVec3::new(0.0, 30.0, 0.0);
    let set = Spheres::new(&row_of_balls()).with_light_grids(&[light]);
    let q = query(DVec3::Y, DVec3::Y, Some((0, Side::Outward)));
    let (tests, factor) = exact_tests(|| set.shadow_to_light(&q, 29.0, 0));
    assert_eq!((tests, factor), (0, 1.0));
}

/// A shadow segment through the centre of the ball nearest the light meets its
/// surface head-on (`l·n = −1`): a factor of 0, which no other occluder can lower, so
/// the ball behind it on the segment is not tested.
#[test]
fn a_shadow_ray_stops_at_a_factor_of_0() {
    let light = DVec3::new(0.0, 30.0, 0.0);
    let set = Spheres::new(&[
        Sphere::new(DVec3::ZERO, 1.0),
        Sphere::new(DVec3::new(0.0, 10.0, 0.0), 1.0),
        Sphere::new(DVec3::new(0.0, 20.0, 0.0), 1.0),
    ])
    .with_light_grids(&[light]);
    let q = query(DVec3::Y, DVec3::Y, Some((0, Side::Outward)));
    let (tests, factor) = exact_tests(|| set.shadow_to_light(&q, 29.0, 0));
    assert_eq!((tests, factor), (1, 0.0));
}

/// The tracer's build gives the eye's grid its per-sphere records (its shortcuts read
/// them) and each light a grid around it.
#[test]
fn the_build_gives_the_eye_its_records_and_each_light_its_grid() {
    let spheres = row_of_balls();
    let lights = [DVec3::new(0.0, 30.0, 0.0), DVec3::new(20.0, 30.0, 5.0)];
    let (set, eye) = Spheres::build_for_view(&spheres, &lights, DVec3::new(0.0, 0.0, 9.0), None);
    assert!(eye.shortcut(spheres.len()).is_some());
    let centres: Vec<DVec3> = set.lights.iter().map(|grid| grid.centre()).collect();
    assert_eq!(centres, lights);
}

/// The cells a face of the eye's and the lights' grids, as docs/speed.md gives them
/// (the minima of sweeps over scene sizes).
#[test]
fn grids_are_as_fine_as_their_scene_s_size_asks() {
    let eye = [
        (0, 12),
        (64, 12),
        (65, 32),
        (256, 32),
        (257, 64),
        (4_096, 64),
        (4_097, 128),
        (65_536, 128),
    ];
    for (spheres, cells) in eye {
        assert_eq!(eye_resolution(spheres), cells, "eye, {spheres} spheres");
    }
    // Above 65,536 spheres the eye has no grid: primary rays walk in bundles.
    for (balls, grid) in [(65_532, true), (65_533, false)] {
        let scene = crate::scene::many_scene(balls);
        let spheres: Vec<_> = scene.spheres.iter().map(|s| (s.center, s.radius)).collect();
        let eye = crate::accel::eye_dir_grid(DVec3::new(0.0, 18.0, 60.0), &spheres, None);
        assert_eq!(eye.is_some(), grid, "{} spheres", spheres.len());
    }
    let light = [
        (0, 64),
        (64, 64),
        (65, 128),
        (4_096, 128),
        (4_097, 256),
        (1 << 20, 256),
    ];
    for (spheres, cells) in light {
        assert_eq!(grid_resolution(spheres), cells, "light, {spheres} spheres");
    }
}

/// The quick test widens a sphere by `32u·|f|` (`u = 2⁻²⁴`, `f` the centre from the
/// ray's origin) for the rounding of the line's distance, which errs by at most `13u·|f|`: a
/// line passing `50u·|f|` outside the sphere is rejected however it rounds. Spheres of
/// radius 10⁻³ to 10³, 20 to 10⁴ radii away, lines in every direction.
#[test]
fn the_quick_test_rejects_a_line_a_few_roundings_outside() {
    let cases = (
        log_uniform(-3.0, 3.0),
        log_uniform(1.3, 4.0),
        unit_vector(),
        unit_vector(),
    );
    runner(20_000)
        .run(&cases, |(r, radii_away, centre_dir, dir)| {
            let away = r * radii_away;
            let centre = centre_dir * away;
            let d = dir.as_vec3().normalize().as_dvec3();
            let w = f64::from(r as f32) * (1.0 + 1e-6);
            // The origin on a line that passes `w + 50u·|f|` from the centre, the
            // centre's foot halfway along the segment.
            let gap = w + 50.0 * 2f64.powi(-24) * away;
            let origin = centre + d.any_orthonormal_vector() * gap - d * away;
            let ray = Ray::new(&query(origin, d, None));
            let f = (origin - centre).length();
            prop_assert!(
                !may_cross(centre, w as f32, &ray, (2.0 * f) as f32),
                "r {r:e}, |f| {f:e}, line {gap:e} from the centre"
            );
            Ok(())
        })
        .unwrap();
}

/// Sphere 1's list of the spheres overlapping it allows `10⁻⁶` of the radii and
/// `10⁻⁹` of the centres' distances from the origin for rounding: a sphere apart by
/// more than twice that is not on it; a sphere touching it, or apart by half of it,
/// is. Small spheres near the origin and large ones far from it.
#[test]
fn overlap_lists_keep_no_sphere_beyond_their_allowance() {
    for (centre, r) in [
        (DVec3::new(1e-3, 0.0, 0.0), 1e-4),
        (DVec3::new(1e4, 0.0, 0.0), 1.0),
    ] {
        let allowance = 2e-6 * r + 2e-9 * 2.0 * centre.length();
        let apart = |gap: f64| Sphere::new(centre + DVec3::new(0.0, 2.0 * r + gap, 0.0), r);
        let set = Spheres::new(&[
            apart(2.0 * allowance),
            Sphere::new(centre, r),
            apart(0.0),
            apart(-0.5 * r),
            apart(0.5 * allowance),
        ]);
        assert_eq!(
            set.overlapping(1, usize::MAX).as_deref(),
            Some(&[2, 3, 4][..]),
            "around {centre} radius {r}"
        );
    }
}

/// A grid's `always` list (the spheres seen in every direction) takes a sphere whose
/// surface passes within `10⁻⁶` of its radius and `10⁻⁹` of `|c − centre|∞` beyond
/// the centre, for rounding: one beyond by half the second term is on it, one
/// beyond by twice that is not. A small sphere near the centre, a large one far off.
#[test]
fn always_lists_the_spheres_around_the_centre_within_their_allowance() {
    let centre = DVec3::new(3.0, -2.0, 1.0);
    for r in [1e-3, 1e3] {
        let beyond = |f: f64| {
            // `|c − centre|∞` is the distance itself, along x.
            let dist = r * (1.0 + 1e-6) / (1.0 - f * 1e-9);
            (centre + DVec3::new(dist, 0.0, 0.0), r)
        };
        let grid = DirGrid::build(centre, &[beyond(0.5), beyond(2.0)], 12, None)
            .expect("within the bound");
        assert_eq!(grid.always, [0], "radius {r}");
    }
}

/// A grid's entry holds a sphere's nearest distance from the centre, `|c − centre| −
/// r`, less a margin for rounding of `10⁻⁶·(|c − centre| + r + |centre|∞)`, rounded
/// down to `f32`: lower by that margin, within a tenth of it (queries stop at the
/// first entry beyond their hit, so a larger margin costs work and a smaller one may
/// lose a hit). A grid far from the origin and one at it.
#[test]
fn grid_entries_hold_the_nearest_distance_less_its_margin() {
    for (centre, rel, r) in [
        (DVec3::new(1e4, -2e3, 5.0), DVec3::new(0.0, 0.0, 3.0), 1.0),
        (DVec3::ZERO, DVec3::new(0.0, 3.0, 0.0), 1.0),
    ] {
        let grid =
            DirGrid::build(centre, &[(centre + rel, r)], 12, None).expect("within the bound");
        let cell = grid.cell(rel.normalize().as_vec3());
        let &[Listed {
            k: 0, near: entry, ..
        }] = grid.candidates(cell)
        else {
            panic!("one entry, sphere 0");
        };
        let dist = rel.length();
        let margin = 1e-6 * (dist + r + centre.abs().max_element());
        let below = (dist - r) - f64::from(entry);
        assert!(
            (0.9 * margin..=1.1 * margin).contains(&below),
            "{below:e} below, margin {margin:e}, grid at {centre}"
        );
    }
}

/// The eye's grid keeps a sphere unless it lies wholly outside a side of the view
/// pyramid by more than `10⁻⁶` of its radius and `10⁻⁹` of its centre's distance
/// and radius: a sphere outside by twice that is dropped; one that touches the side,
/// or lies outside by the allowance less `0.5·10⁻⁹·r` (half the radius's share of
/// it), is kept. Small spheres near the eye, and small and large ones far from it.
#[test]
fn the_view_pyramid_drops_a_sphere_just_beyond_its_allowance() {
    // The film spans x and y in [−1, 1] at z = −1: the pyramid's right side leans out
    // by the film's margin of 10⁻³.
    let view = ViewPyramid::new(
        DVec3::ZERO,
        DVec3::new(-1.0, -1.0, -1.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
    )
    .expect("a proper pyramid");
    let edge = 1.0 + 2e-3;
    let outward = DVec3::new(1.0, 0.0, edge).normalize();
    for (depth, r) in [(1e-3, 1e-5), (1e4, 1.0), (1e4, 100.0)] {
        let on_side = DVec3::new(edge * depth, 0.0, -depth);
        let allowance = 2e-6 * r + 2e-9 * (on_side.abs().max_element() + r);
        let at = |gap: f64| on_side + outward * (r + gap);
        assert!(view.may_see(at(0.0), r), "touching, depth {depth}");
        let reach = 1e-6 * r + 1e-9 * (at(0.0).abs().max_element() + r);
        assert!(
            view.may_see(at(reach - 0.5e-9 * r), r),
            "just inside, depth {depth}"
        );
        assert!(
            !view.may_see(at(2.0 * allowance), r),
            "beyond, depth {depth}"
        );
    }
}
