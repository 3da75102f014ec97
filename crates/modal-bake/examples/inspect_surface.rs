//! Times the surface inspection (`modal_bake::mesh::surface::inspect_surface`) on an asset:
//! reads it once, inspects it RUNS times, prints the counts and the median seconds.
//!
//! `cargo run --release -p modal-bake --example inspect_surface -- ASSET [RUNS]`

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("usage: inspect_surface ASSET.obj|stl|ply [RUNS]")?;
    let runs: usize = args.next().map_or(Ok(5), |r| r.parse())?;
    let s = modal_bake::mesh::surface::read_surface(path.as_ref())?;
    let mut times = Vec::with_capacity(runs);
    let mut found = None;
    for _ in 0..runs.max(1) {
        let t = std::time::Instant::now();
        found = Some(modal_bake::mesh::surface::inspect_surface(&s));
        times.push(t.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let i = found.ok_or("no run")?;
    println!(
        "{path}: {} vertices, {} triangles: {}; inspection median {:.4} s over {} runs (min {:.4} s)",
        i.vertices,
        i.triangles,
        i.summary(),
        times[times.len() / 2],
        times.len(),
        times[0]
    );
    Ok(())
}
