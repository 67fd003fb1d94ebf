//! `bench-gpu`: times gpu-shoot on the built-in Cornell box at about 127k
//! covered texels (the size of paper 004's "Cornell box high") to 90%
//! convergence: hemicube vs stereographic, with and without ambient
//! overshooting (004 Table 4.1). With `--detail`, the shape of 004 Table
//! 2.1 instead: a closed box with and without a normal map on its walls,
//! the Cornell box with and without adaptive subdivision (one level), at
//! `--texels` (default 8000 there) to 99%. Table on stderr, RON on stdout
//! or `-o`.

use clap::Parser;
use glam::DVec3;
use gpu_shoot::{gpu, solve, Adaptive, Params, Visibility};
use schemas::header::{Provenance, Schema};
use schemas::mesh::Mesh;
use schemas::surface::{Surface, Texture, TextureKind, NONE};
use serde::Serialize;
use std::path::PathBuf;
use std::process::ExitCode;
use test_support::meshes;

/// Benchmark arguments.
#[derive(Parser, Debug)]
#[command(name = "bench-gpu", version)]
struct Args {
    /// Output: the RON report (default: stdout).
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Covered texels to aim for [default: 127000, with --detail 8000].
    #[arg(long)]
    texels: Option<f64>,
    /// Convergence to reach [default: 0.9, with --detail 0.99].
    #[arg(long)]
    convergence: Option<f64>,
    /// The surface detail table (004 Table 2.1's shape) instead.
    #[arg(long)]
    detail: bool,
}

/// One row of the surface detail table.
#[derive(Serialize, Debug)]
struct DetailRow {
    scene: String,
    texels: usize,
    shots: usize,
    setup_seconds: f64,
    shoot_seconds: f64,
    subdivision_seconds: f64,
}

/// A normal map of 64 x 64 texels: bumps `sin(2 pi 4 u) sin(2 pi 4 v)`
/// tilting the normal by up to about 27 degrees.
fn bumps() -> Texture {
    let n = 64;
    let texels = (0..n * n)
        .map(|k| {
            let (u, v) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
            let (a, b) = (0.5 * (8.0 * std::f64::consts::PI * u).cos(), 0.5 * (8.0 * std::f64::consts::PI * v).cos());
            let m = DVec3::new(a, b, 1.0).normalize();
            [((m.x + 1.0) / 2.0) as f32, ((m.y + 1.0) / 2.0) as f32, ((m.z + 1.0) / 2.0) as f32, 1.0]
        })
        .collect();
    Texture { kind: TextureKind::Normal, width: n, height: n, texels, scale: [1.0, 1.0], offset: [0.0, 0.0], clamp: false, strength: 1.0 }
}

/// The normal map on every triangle of material 0 of `mesh`: coordinates
/// along its first edge and the in-plane direction across it, one unit a
/// metre, the tangent along the first edge.
fn normal_mapped(mesh: &Mesh, materials: usize) -> Surface {
    let (mut uvs, mut tangents) = (Vec::new(), Vec::new());
    for (t, tri) in mesh.triangles.iter().enumerate().filter(|(_, tri)| tri.material == 0) {
        let p = tri.vertices.map(|v| DVec3::from(mesh.positions[v as usize].map(f64::from)));
        let tangent = (p[1] - p[0]).normalize();
        let across = DVec3::from(tri.normal.map(f64::from)).cross(tangent);
        uvs.push((t as u32, p.map(|q| [q.dot(tangent) as f32, q.dot(across) as f32])));
        tangents.push((t as u32, [tangent.x as f32, tangent.y as f32, tangent.z as f32, 1.0]));
    }
    let mut material_maps = vec![[NONE; 3]; materials];
    material_maps[0] = [NONE, NONE, 0];
    Surface { header: Surface::header(Provenance::in_memory("bench-gpu")), uvs, shading_normals: Vec::new(), tangents, material_maps, textures: vec![bumps()] }
}

/// The surface detail table: time, texels (the paper's elements), shots
/// and the time spent subdividing.
fn detail(device: &wgpu::Device, queue: &wgpu::Queue, texels: f64, convergence: f64) -> Result<Vec<DetailRow>, String> {
    let mesh = meshes::closed_box(1.0, 0.3);
    let m = meshes::manifest(2, vec![meshes::material([0.7; 3], [0.0; 3]), meshes::material([0.7; 3], [10.0; 3])]);
    let bumpy = normal_mapped(&mesh, 2);
    let (cornell, cornell_manifest) = mesh_prep::prepare_builtin("cornell-box", "bench-gpu").map_err(|e| e.to_string())?;
    let base = Params { texels, convergence_target: convergence, ..Params::default() };
    let adaptive = Params { adaptive: Some(Adaptive { levels: 1, ..Adaptive::default() }), ..base.clone() };
    let cases: [(&str, &Mesh, &schemas::mesh::Manifest, Option<&Surface>, &Params); 4] = [
        ("box", &mesh, &m, None, &base),
        ("box, normal map", &mesh, &m, Some(&bumpy), &base),
        ("Cornell box", &cornell, &cornell_manifest, None, &base),
        ("Cornell box, adaptive", &cornell, &cornell_manifest, None, &adaptive),
    ];
    eprintln!("{:>22} {:>8} {:>6} {:>9} {:>9} {:>12}", "scene", "texels", "shots", "setup s", "shoot s", "subdivide s");
    let mut rows = Vec::new();
    for (scene, mesh, manifest, surface, params) in cases {
        let solved = solve(device, queue, mesh, manifest, surface, &[], params, &mut |_| {})?;
        let w = &solved.work;
        let row = DetailRow { scene: scene.into(), texels: solved.atlas.texels.len(), shots: w.shots, setup_seconds: w.setup_seconds, shoot_seconds: w.shoot_seconds, subdivision_seconds: w.subdivision_seconds };
        eprintln!("{:>22} {:>8} {:>6} {:>9.3} {:>9.3} {:>12.3}", row.scene, row.texels, row.shots, row.setup_seconds, row.shoot_seconds, row.subdivision_seconds);
        rows.push(row);
    }
    Ok(rows)
}

/// One configuration's result.
#[derive(Serialize, Debug)]
struct Row {
    visibility: String,
    overshoot: bool,
    texels: usize,
    shots: usize,
    unshot_fraction: f64,
    setup_seconds: f64,
    shoot_seconds: f64,
}

/// The report.
#[derive(Serialize, Debug)]
struct Bench {
    adapter: String,
    rows: Vec<Row>,
    detail: Vec<DetailRow>,
}

fn run(args: Args) -> Result<ExitCode, String> {
    let (device, queue, info) = gpu::acquire()?;
    let adapter = gpu::describe(&info);
    if args.detail {
        let (texels, convergence) = (args.texels.unwrap_or(8000.0), args.convergence.unwrap_or(0.99));
        eprintln!("bench-gpu --detail: {texels} texels, to {:.0}% on {adapter}", 100.0 * convergence);
        let detail = detail(&device, &queue, texels, convergence)?;
        return write(&args, &Bench { adapter, rows: Vec::new(), detail });
    }
    let (texels, convergence) = (args.texels.unwrap_or(127_000.0), args.convergence.unwrap_or(0.9));
    let (mesh, manifest) = mesh_prep::prepare_builtin("cornell-box", "bench-gpu").map_err(|e| e.to_string())?;
    let mut rows = Vec::new();
    eprintln!("bench-gpu: Cornell box, {} triangles, to {:.0}% on {adapter}", mesh.triangles.len(), 100.0 * convergence);
    eprintln!("{:>14} {:>9} {:>8} {:>6} {:>9} {:>9}", "visibility", "overshoot", "texels", "shots", "setup s", "shoot s");
    for visibility in [Visibility::Hemicube, Visibility::Stereographic] {
        for overshoot in [false, true] {
            let params = Params { texels, visibility, overshoot, convergence_target: convergence, ..Params::default() };
            let solved = solve(&device, &queue, &mesh, &manifest, None, &[], &params, &mut |_| {})?;
            let row = Row {
                visibility: format!("{visibility:?}").to_lowercase(),
                overshoot,
                texels: solved.atlas.texels.len(),
                shots: solved.work.shots,
                unshot_fraction: solved.shots.last().map_or(1.0, |s| s.unshot_magnitude_fraction),
                setup_seconds: solved.work.setup_seconds,
                shoot_seconds: solved.work.shoot_seconds,
            };
            eprintln!("{:>14} {:>9} {:>8} {:>6} {:>9.3} {:>9.3}", row.visibility, row.overshoot, row.texels, row.shots, row.setup_seconds, row.shoot_seconds);
            rows.push(row);
        }
    }
    write(&args, &Bench { adapter, rows, detail: Vec::new() })
}

/// Writes the report where `args` says.
fn write(args: &Args, bench: &Bench) -> Result<ExitCode, String> {
    let text = ron::ser::to_string_pretty(bench, Default::default()).map_err(|e| e.to_string())?;
    match &args.output {
        Some(p) => std::fs::write(p, text + "\n").map_err(|e| format!("{}: {e}", p.display()))?,
        None => println!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    gpu::quiet_device_select_layer();
    match run(Args::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("bench-gpu: error: {e}");
            ExitCode::from(2)
        }
    }
}
