//! The pixel inspector: a click prints the pixel (`j` from the bottom, as in GLUT),
//! the sphere its centre ray hits and the whole ray tree, traced again by the `f64`
//! reference with a recorder ([`ReferenceTracer::inspect`]). Spheres and lights are
//! counted from 1, as a scene file's `[[sphere]]` and `[[light]]` tables are in its
//! error messages (the tracer's records count from 0).

use std::fmt::Write;
use std::sync::mpsc::{self, Sender};
use std::sync::Arc;

use glam::{DVec3, Vec3};

use crate::image_io::ByteEncoder;
use crate::scene::Scene;
use crate::trace::reference::{RayNode, ReferenceTracer};

fn v3(v: DVec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

/// A click to answer: pixel `(i, j)` of a `width`×`height` view of `scene`, and its
/// value on screen.
pub struct Request {
    /// The scene, its camera the view's.
    pub scene: Arc<Scene>,
    /// The view's width and height.
    pub size: (u32, u32),
    /// `(i, j)`, `j` from the bottom.
    pub pixel: (u32, u32),
    /// The pixel's value on screen.
    pub shown: Vec3,
}

/// The thread that answers clicks, one at a time and in order, printing each report.
/// Each builds the `f64` tracer of the whole scene (tens of MB for 100,000 spheres):
/// clicks in quick succession wait their turn rather than build side by side. The
/// thread ends once the window has let go of this handle and the queue is empty.
pub struct Inspector {
    requests: Sender<Request>,
}

impl Inspector {
    /// Starts the thread.
    pub fn spawn() -> Inspector {
        let (requests, queue) = mpsc::channel::<Request>();
        std::thread::Builder::new()
            .name("whitted-inspect".into())
            .spawn(move || {
                for r in queue {
                    let ((w, h), (i, j)) = (r.size, r.pixel);
                    match report(&r.scene, w, h, i, j, r.shown) {
                        Ok(text) => print!("{text}"),
                        Err(e) => eprintln!("whitted: cannot inspect the pixel: {e}"),
                    }
                }
            })
            .expect("cannot start the inspector thread");
        Inspector { requests }
    }

    /// Queues a click.
    pub fn inspect(&self, request: Request) {
        // The thread only ends when this sender is dropped.
        let _ = self.requests.send(request);
    }
}

/// The report for pixel `(i, j)` of a `width`×`height` view of `scene` (whose camera
/// is the view's); `shown` is the pixel's value on screen.
pub fn report(
    scene: &Scene,
    width: u32,
    height: u32,
    i: u32,
    j: u32,
    shown: Vec3,
) -> Result<String, String> {
    let camera = scene
        .camera(width, height)
        .map_err(|e| format!("camera: {e}"))?;
    let settings = scene.settings();
    let tracer = ReferenceTracer::new(scene, camera, settings.quality.max_depth);
    let s = (f64::from(i) + 0.5) / f64::from(width);
    let t = (f64::from(j) + 0.5) / f64::from(height);
    let (colour, tree) = tracer.inspect(s, t);
    let encoder = ByteEncoder::new(settings.encoding);
    let bytes = shown.to_array().map(|c| encoder.byte(c));
    let mut out = String::new();
    let _ = writeln!(
        out,
        "pixel i={i} j={j} (j from the bottom) of {width}x{height}: on screen {} = {bytes:?}",
        v3(shown.as_dvec3())
    );
    match tree.hit {
        Some(hit) => {
            let _ = writeln!(
                out,
                "  hit sphere {} at {}, {}",
                hit.sphere + 1,
                v3(hit.point),
                if hit.entering {
                    "from outside"
                } else {
                    "from inside"
                }
            );
        }
        None => {
            let _ = writeln!(out, "  hit nothing: sky");
        }
    }
    let _ = writeln!(
        out,
        "  ray tree of the pixel centre (f64 reference, colour {}):",
        v3(colour)
    );
    write_node(&mut out, &tree, 2);
    Ok(out)
}

fn write_node(out: &mut String, node: &RayNode, indent: usize) {
    let pad = " ".repeat(indent);
    let target = match (node.hit, node.depth_limited) {
        (_, true) => "depth limit: sky".to_string(),
        (Some(hit), _) => format!("sphere {}", hit.sphere + 1),
        (None, _) => "sky".to_string(),
    };
    let _ = writeln!(
        out,
        "{pad}{:<8} depth {} {:<14} weight {:.4} colour {}",
        node.kind.name(),
        node.depth,
        target,
        node.weight,
        v3(node.colour)
    );
    for shadow in &node.shadows {
        let occluder = match shadow.occluder {
            Some(k) => format!("blocked by sphere {}", k + 1),
            None => "unblocked".to_string(),
        };
        let _ = writeln!(
            out,
            "{pad}  {:<8} light {} {occluder}, factor {:.4}, weight {:.4} colour {}",
            "shadow",
            shadow.light + 1,
            shadow.factor,
            shadow.weight,
            v3(shadow.colour)
        );
    }
    for child in &node.children {
        write_node(out, child, indent + 2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{hw3_scene, HW3_DEFAULT_SEED};
    use crate::trace::reference::RayKind;
    use crate::trace::RayCounts;

    /// What the tree says the pixel is: every leaf (a shadow ray's light term, or a ray
    /// that saw the sky) times its weight.
    fn leaf_sum(node: &RayNode) -> DVec3 {
        let mut sum = DVec3::ZERO;
        if node.hit.is_none() || node.depth_limited {
            sum += node.colour * node.weight;
        }
        for s in &node.shadows {
            sum += s.colour * s.weight;
        }
        for c in &node.children {
            sum += leaf_sum(c);
        }
        sum
    }

    fn count(node: &RayNode, counts: &mut RayCounts) {
        if !node.depth_limited {
            match node.kind {
                RayKind::Primary => counts.primary += 1,
                _ => counts.secondary += 1,
            }
        }
        counts.shadow += node.shadows.len() as u64;
        for c in &node.children {
            count(c, counts);
        }
    }

    #[test]
    fn the_tree_adds_up_to_the_reference_colour() {
        let scene = hw3_scene(HW3_DEFAULT_SEED);
        let (w, h) = (64, 36);
        let camera = scene.camera(w, h).unwrap();
        let tracer = ReferenceTracer::new(&scene, camera, scene.settings().quality.max_depth);
        let mut deepest = 0;
        for j in 0..h {
            for i in 0..w {
                let (s, t) = ((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
                let mut counts = RayCounts::default();
                let plain = tracer.sample_f64(s, t, &mut counts);
                let (colour, tree) = tracer.inspect(s, t);
                // Recording changes nothing.
                assert_eq!(colour, plain);
                assert_eq!(tree.colour, plain);
                assert_eq!(tree.kind, RayKind::Primary);
                let mut seen = RayCounts::default();
                count(&tree, &mut seen);
                assert_eq!(seen, counts, "pixel ({i}, {j})");
                let sum = leaf_sum(&tree);
                assert!(
                    (sum - plain).abs().max_element() < 1e-9,
                    "pixel ({i}, {j}): leaves {sum} vs {plain}"
                );
                deepest = deepest.max(depth(&tree));
            }
        }
        // The scene has mirrors and glass: some trees go several bounces deep.
        assert!(deepest >= 3, "deepest tree {deepest}");
    }

    fn depth(node: &RayNode) -> u32 {
        node.children.iter().map(depth).max().unwrap_or(node.depth)
    }

    #[test]
    fn the_report_names_the_pixel_the_hit_and_the_rays() {
        let scene = hw3_scene(HW3_DEFAULT_SEED);
        // The bottom row looks at the ground sphere; the top row at the sky.
        let text = report(&scene, 64, 36, 10, 0, Vec3::new(0.5, 1.0, 0.0)).unwrap();
        assert!(text.starts_with("pixel i=10 j=0 (j from the bottom) of 64x36"));
        assert!(text.contains("[128, 255, 0]"), "{text}");
        // The ground is the first [[sphere]] of the file: sphere 1, as in its errors.
        assert!(text.contains("hit sphere 1 at"), "{text}");
        assert!(text.contains("primary  depth 0 sphere 1 "), "{text}");
        assert!(text.contains("shadow   light 1 "), "{text}");
        assert!(
            !text.contains("sphere 0") && !text.contains("light 0"),
            "{text}"
        );
        let sky = report(&scene, 64, 36, 10, 35, Vec3::ONE).unwrap();
        assert!(sky.contains("hit nothing: sky"), "{sky}");
    }
}
