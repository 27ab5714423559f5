//! Development aid: statistics and timings of the fast tracer's acceleration structures
//! for a scene file (`cargo run --release --example gridstats -- scene.toml`).
use std::time::Instant;
fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: gridstats SCENE.toml");
    let scene = whitted::Scene::load(std::path::Path::new(&path)).unwrap();
    let cam = whitted::Camera::for_scene(&scene, 1280, 720).unwrap();
    let t = Instant::now();
    let sph = whitted::accel::Spheres::new(&scene.spheres);
    println!("bvh build {:.4} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let sph = sph.with_grids(cam.origin, &[scene.lights[0].position]);
    println!("grids build {:.4} s", t.elapsed().as_secs_f64());
    sph.debug_stats();
}
