//! Development aid: peak memory of rendering many_N built in code (no scene file):
//! `/usr/bin/time -f %M cargo run --release --example many_peak -- 100000`.
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(100_000, |a| a.parse().expect("a count"));
    let scene = whitted::scene::many_scene(n);
    let opts = scene.settings();
    let (_, stats) = whitted::render(&scene, &opts, &Default::default()).expect("renders");
    println!(
        "{n} spheres: {:.3} s ({:.3} s build), {} rays",
        stats.seconds,
        stats.build_seconds,
        stats.rays.total()
    );
}
