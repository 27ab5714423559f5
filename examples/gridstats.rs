use std::time::Instant;
use whitted::accel::Query;
fn main() {
    let scene = whitted::scene::hw3_scene(2020);
    let cam = whitted::Camera::for_scene(&scene, 1280, 720).unwrap();
    let sph = whitted::accel::Spheres::new(&scene.spheres).with_grids(cam.origin.as_vec3().as_dvec3(), &[scene.lights[0].position.as_vec3().as_dvec3()]);
    sph.debug_stats();
    let o = cam.origin.as_vec3();
    for (name, rows) in [("ground", 0..300u32), ("horizon", 300..420), ("sky", 420..720)] {
        let mut dirs = Vec::new();
        for j in rows.clone() { for i in 0..1280u32 {
            let s = (i as f32 + 0.5) / 1280.0; let t = (j as f32 + 0.5) / 720.0;
            dirs.push((cam.lower_left.as_vec3() + cam.horizontal.as_vec3() * s + cam.vertical.as_vec3() * t - o).normalize());
        }}
        let start = Instant::now();
        let mut hits = 0;
        for _ in 0..1 { for &d in dirs.iter().step_by(16) {
            if sph.closest_primary(&Query { origin: o, dir: d, from: None }).is_some() { hits += 1; }
        }}
        let ns = start.elapsed().as_secs_f64() * 1e9 / (dirs.len() / 16) as f64;
        let start = Instant::now();
        for _ in 0..1 { for &d in dirs.iter().step_by(16) {
            if sph.closest(&Query { origin: o, dir: d, from: None }).is_some() { hits += 1; }
        }}
        let ns_bvh = start.elapsed().as_secs_f64() * 1e9 / (dirs.len() / 16) as f64;
        println!("{name}: grid {ns:.1} ns/ray, bvh {ns_bvh:.1} ns/ray, hits {hits}");
    }
}
