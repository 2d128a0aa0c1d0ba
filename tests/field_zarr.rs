//! Chunked fields (issue 33): a field computed box by box equals the whole computation
//! for every method, the Zarr array's layout and metadata, partial arrays and their
//! resumption, and the command line's refusals (exit status 2).

mod common;

use common::{Rng, bumpy_sphere, random_wire};
use glam::DVec3;
use serde_json::Value;
use smoothtrace::field::zarr::{Codec, ZarrArray, ZarrSpec, grid_attributes, write_chunks};
use smoothtrace::field::{self, FieldOptions, FieldPlan, FieldSource, Grid, Method, VoxelBox};
use smoothtrace::mesh::Mesh;
use smoothtrace::primitives::PrimitiveKind;
use std::sync::atomic::AtomicBool;

/// Tolerance of the comparisons, times the mesh diagonal (linfac's spans start at other
/// pixels in a box, so its f64 interpolation may differ by rounding).
const TOL: f64 = 1e-6;

const KINDS: [PrimitiveKind; 3] = [
    PrimitiveKind::Points,
    PrimitiveKind::Edges,
    PrimitiveKind::Triangles,
];

/// The boxes of a chunk grid of `c` voxels a side over `grid` (cut at the far edges).
fn boxes(grid: &Grid, c: [usize; 3]) -> Vec<VoxelBox> {
    let mut out = Vec::new();
    for z in (0..grid.res[2]).step_by(c[2]) {
        for y in (0..grid.res[1]).step_by(c[1]) {
            for x in (0..grid.res[0]).step_by(c[0]) {
                let start = [x, y, z];
                out.push(VoxelBox {
                    start,
                    size: [0, 1, 2].map(|a| c[a].min(grid.res[a] - start[a])),
                });
            }
        }
    }
    out
}

/// The field assembled from boxes of `c` voxels, in the whole grid's layout.
fn assembled(plan: &FieldPlan, c: [usize; 3]) -> Vec<f32> {
    let grid = *plan.grid();
    let mut out = vec![f32::NAN; grid.len()];
    for b in boxes(&grid, c) {
        let mut v = vec![f32::NAN; b.len()];
        plan.compute_box(&b, &mut v);
        let [sx, sy, sz] = b.size;
        for k in 0..sz {
            for j in 0..sy {
                let row = &v[(k * sy + j) * sx..][..sx];
                let at = grid.index(b.start[0], b.start[1] + j, b.start[2] + k);
                out[at..at + sx].copy_from_slice(row);
            }
        }
    }
    out
}

fn assert_close(got: &[f32], want: &[f32], tol: f64, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    let mut worst = (0.0f64, 0usize);
    for (n, (&g, &w)) in got.iter().zip(want).enumerate() {
        let d = if g == w {
            0.0
        } else {
            (g as f64 - w as f64).abs()
        };
        assert!(!d.is_nan(), "{what}: voxel {n} is {g}, whole {w}");
        if d > worst.0 {
            worst = (d, n);
        }
    }
    assert!(
        worst.0 <= tol,
        "{what}: voxel {} is {} in boxes, {} whole: difference {:e} > tolerance {:e}",
        worst.1,
        got[worst.1],
        want[worst.1],
        worst.0,
        tol
    );
}

fn check_boxes(mesh: &Mesh, kind: PrimitiveKind, grid: &Grid, method: Method, o: &FieldOptions) {
    let what = format!("{} {kind} {} band {:?}", mesh.name, method.name(), o.band);
    let (whole, _) = field::compute(mesh, kind, grid, method, o).unwrap();
    let plan = FieldPlan::new(mesh, kind, grid, method, o).unwrap();
    let tol = TOL * grid.diagonal();
    for c in [
        [7, 5, 6],
        [grid.res[0], 3, 1],
        [1, grid.res[1], grid.res[2]],
    ] {
        assert_close(
            &assembled(&plan, c),
            &whole.values,
            tol,
            &format!("{what}, boxes {c:?}"),
        );
    }
}

#[test]
fn boxes_equal_the_whole_field_for_every_method() {
    let sphere = bumpy_sphere(12, 16);
    let grid = Grid::around(sphere.bounds(), 19).unwrap();
    for kind in KINDS {
        for method in [Method::Linfac, Method::Bvh, Method::Brute] {
            check_boxes(&sphere, kind, &grid, method, &FieldOptions::default());
        }
        let band = FieldOptions {
            band: Some(0.1 * grid.diagonal()),
            ..FieldOptions::default()
        };
        check_boxes(&sphere, kind, &grid, Method::Linfac, &band);
        check_boxes(&sphere, kind, &grid, Method::Bvh, &band);
        let nocull = FieldOptions {
            cull: false,
            ..FieldOptions::default()
        };
        check_boxes(&sphere, kind, &grid, Method::Linfac, &nocull);
    }
    let smooth = Method::Smooth {
        alpha: 200.0 / grid.diagonal(),
        max_alpha: 200.0 / grid.diagonal(),
        beta: 0.5,
    };
    check_boxes(
        &sphere,
        PrimitiveKind::Triangles,
        &grid,
        smooth,
        &FieldOptions::default(),
    );
    let wire = random_wire(&mut Rng::new(33), 6, 9);
    let grid = Grid::new(DVec3::splat(-1.3), DVec3::new(1.2, 1.1, 1.4), [17, 13, 11]).unwrap();
    check_boxes(
        &wire,
        PrimitiveKind::Edges,
        &grid,
        Method::Linfac,
        &FieldOptions::default(),
    );
}

#[test]
fn boxes_equal_the_whole_field_on_the_bunny() {
    let Some(path) = common::data_file("bunny-7k.obj") else {
        return;
    };
    let m = Mesh::load(&path).unwrap();
    let grid = Grid::around(m.bounds(), 48).unwrap();
    let o = FieldOptions::default();
    let (whole, _) =
        field::compute(&m, PrimitiveKind::Triangles, &grid, Method::Linfac, &o).unwrap();
    let plan = FieldPlan::new(&m, PrimitiveKind::Triangles, &grid, Method::Linfac, &o).unwrap();
    let tol = TOL * grid.diagonal();
    assert_close(
        &assembled(&plan, [16, 16, 16]),
        &whole.values,
        tol,
        "bunny-7k, 16^3 chunks",
    );
}

#[test]
fn sub_grids_keep_the_voxel_centres() {
    let g = Grid::new(
        DVec3::new(-1.0, 0.5, 2.0),
        DVec3::new(3.0, 1.5, 2.7),
        [9, 5, 7],
    )
    .unwrap();
    let b = VoxelBox {
        start: [2, 1, 3],
        size: [7, 4, 2],
    };
    let s = g.sub_grid(&b);
    assert_eq!(s.res, [7, 4, 2]);
    assert_eq!(s.max, DVec3::new(3.0, 1.5, g.min.z + 0.7 * 5.0 / 7.0));
    for (i, j, k) in [(0, 0, 0), (6, 3, 1), (3, 2, 0)] {
        let d = s.voxel_center(i, j, k) - g.voxel_center(i + 2, j + 1, k + 3);
        assert!(d.abs().max_element() <= 1e-15, "{d:?}");
    }
    assert_eq!(g.sub_grid(&VoxelBox::whole(&g)), g);
    assert!(!b.fits(&Grid::new(g.min, g.max, [8, 5, 7]).unwrap()));
}

fn spec(grid: &Grid, chunk: [usize; 3], codec: Codec) -> ZarrSpec {
    ZarrSpec {
        shape: grid.shape(),
        chunk,
        codec,
        attributes: grid_attributes(grid, serde_json::json!({"method": "test"})),
    }
}

#[test]
fn arrays_hold_the_field_in_npy_layout_with_nan_padding() {
    let m = bumpy_sphere(8, 10);
    let grid = Grid::new(DVec3::splat(-1.5), DVec3::new(1.5, 1.2, 1.0), [11, 9, 7]).unwrap();
    let o = FieldOptions::default();
    let (whole, _) = field::compute(&m, PrimitiveKind::Triangles, &grid, Method::Bvh, &o).unwrap();
    let plan = FieldPlan::new(&m, PrimitiveKind::Triangles, &grid, Method::Bvh, &o).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for codec in [Codec::Raw, Codec::Gzip(1)] {
        let path = dir.path().join(format!("{codec:?}.zarr"));
        let s = spec(&grid, [4, 4, 5], codec);
        assert_eq!(s.chunk_grid(), [2, 3, 3]);
        let a = ZarrArray::create(&path, &s, false).unwrap();
        assert_eq!(a.missing().len(), 18);
        let all: Vec<usize> = (0..18).collect();
        let run = write_chunks(&plan, &a, &all, &AtomicBool::new(false), &|_| {}).unwrap();
        assert_eq!((run.written, run.voxels), (18, grid.len() as u64));
        assert!(a.missing().is_empty());
        // Bitwise equal: bvh evaluates the same voxel centres.
        assert_close(
            &a.read_all().unwrap(),
            &whole.values,
            0.0,
            &format!("{codec:?}"),
        );
        // An edge chunk is stored whole, NaN past the array's edge.
        let edge = std::fs::read(path.join("c/1/2/2")).unwrap();
        if codec == Codec::Raw {
            assert_eq!(edge.len(), 4 * 4 * 4 * 5);
            let last = f32::from_le_bytes(edge[edge.len() - 4..].try_into().unwrap());
            assert!(last.is_nan());
        }
        // The metadata is Zarr v3 with the grid in the attributes.
        let meta: Value =
            serde_json::from_str(&std::fs::read_to_string(path.join("zarr.json")).unwrap())
                .unwrap();
        assert_eq!(meta["zarr_format"], 3);
        assert_eq!(meta["shape"], serde_json::json!([7, 9, 11]));
        assert_eq!(
            meta["chunk_grid"]["configuration"]["chunk_shape"],
            serde_json::json!([4, 4, 5])
        );
        assert_eq!(meta["fill_value"], "NaN");
        assert_eq!(
            meta["attributes"]["voxel_size"],
            serde_json::json!(grid.spacing().to_array())
        );
        assert_eq!(
            meta["attributes"]["bounds"][1],
            serde_json::json!(grid.max.to_array())
        );
        // Reopened, it is the same array.
        let b = ZarrArray::open(&path).unwrap();
        assert_eq!(b.spec(), &s);
        b.check_matches(&s).unwrap();
    }
}

#[test]
fn partial_arrays_say_what_is_missing_and_refuse_other_fields() {
    let m = bumpy_sphere(6, 8);
    let grid = Grid::around(m.bounds(), 10).unwrap();
    let plan = FieldPlan::new(
        &m,
        PrimitiveKind::Points,
        &grid,
        Method::Bvh,
        &FieldOptions::default(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.zarr");
    let s = spec(&grid, [4, 4, 4], Codec::Raw);
    let n = s.chunk_count();
    let a = ZarrArray::open_or_create(&path, &s).unwrap();
    write_chunks(&plan, &a, &[1, 2, 5], &AtomicBool::new(false), &|_| {}).unwrap();
    let missing = a.missing();
    assert_eq!(missing.len(), n - 3);
    assert!(!missing.contains(&2) && missing.contains(&0));
    // A stopped run writes nothing more and says so.
    let run = write_chunks(&plan, &a, &[0], &AtomicBool::new(true), &|_| {}).unwrap();
    assert!(run.interrupted && run.written == 0);
    // A chunk of the wrong size counts as missing.
    std::fs::write(a.chunk_path(2), b"short").unwrap();
    assert!(a.missing().contains(&2));
    // Opening again with the same spec works; another field is refused by name.
    ZarrArray::open_or_create(&path, &s).unwrap();
    let mut other = s.clone();
    other.attributes["field"]["method"] = "linfac".into();
    let e = ZarrArray::open_or_create(&path, &other)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("attributes.field.method") && e.contains("\"test\""),
        "{e}"
    );
    let e = ZarrArray::create(&path, &s, false).unwrap_err().to_string();
    assert!(e.contains("already exists") && e.contains("--force"), "{e}");
    // A corrupt zarr.json is named.
    std::fs::write(path.join("zarr.json"), "{\"zarr_format\": 2").unwrap();
    let e = ZarrArray::open(&path).unwrap_err().to_string();
    assert!(e.contains("not valid JSON"), "{e}");
    // --force replaces an array, but never a folder that is not one.
    ZarrArray::create(&path, &s, true).unwrap();
    assert_eq!(ZarrArray::open(&path).unwrap().missing().len(), n);
    let plain = dir.path().join("plain");
    std::fs::create_dir(&plain).unwrap();
    std::fs::write(plain.join("notes.txt"), "keep").unwrap();
    let e = ZarrArray::create(&plain, &s, true).unwrap_err().to_string();
    assert!(e.contains("not a Zarr array"), "{e}");
    assert!(plain.join("notes.txt").exists());
}

/// Runs the built binary with `args` in `dir`, returning (status code, stderr).
fn smoothtrace(dir: &std::path::Path, args: &[&str]) -> (i32, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("cannot run smoothtrace");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn cli_writes_zarr_in_parts_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let m = bumpy_sphere(8, 12);
    let mut obj = String::new();
    for v in &m.vertices {
        obj += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in &m.triangles {
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(d.join("s.obj"), obj).unwrap();
    let base = [
        "field",
        "s.obj",
        "-p",
        "triangles",
        "--res-xyz",
        "20",
        "20",
        "20",
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    let run = |extra: &[&str]| {
        let args = with(extra);
        smoothtrace(d, &args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let (code, err) = run(&["-o", "s.npy"]);
    assert_eq!(code, 0, "{err}");
    let npy: Vec<f32> = npyz::NpyFile::new(&std::fs::read(d.join("s.npy")).unwrap()[..])
        .unwrap()
        .into_vec()
        .unwrap();
    // Two "jobs" of a job array, then a resume.
    let (code, err) = run(&["-o", "v.zarr", "--chunk", "8", "--chunks", "0:5"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("partial") && err.contains("--chunks 5:"),
        "{err}"
    );
    let (code, err) = run(&["-o", "v.zarr", "--chunk", "8", "--chunks", "9:"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("--chunks 5:9"), "{err}");
    let (code, err) = run(&["-o", "v.zarr", "--chunk", "8", "--resume"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("4 to compute") && err.contains("complete"),
        "{err}"
    );
    let a = ZarrArray::open(&d.join("v.zarr")).unwrap();
    let tol = TOL * 2.0;
    assert_close(&a.read_all().unwrap(), &npy, tol, "cli zarr vs npy");
    // Refusals, each with exit status 2 and the reason.
    for (extra, needle) in [
        (&["-o", "v.zarr", "--chunk", "8"][..], "already exists"),
        (
            &["-o", "v.zarr", "--chunk", "4", "--resume"][..],
            "chunk shape",
        ),
        (&["-o", "w.zarr", "--chunk", "0"][..], "at least 1"),
        (
            &["-o", "w.zarr", "--chunk", "21"][..],
            "larger than the volume",
        ),
        (
            &["-o", "w.zarr", "--chunk", "8", "--chunks", "20:30"][..],
            "27 chunks",
        ),
        (&["-o", "w.zarr", "--resume"][..], "nothing to resume"),
        (
            &["-o", "s.npy", "--chunk", "8"][..],
            "applies to chunked outputs",
        ),
        (&["-o", "w.zarr", "--preview", "p.png"][..], "--preview"),
        (&["-o", "missing/w.zarr"][..], "cannot create"),
        (
            &["-o", "v.zarr", "--chunk", "8", "--resume", "--band", "0.1"][..],
            "attributes.field.band",
        ),
    ] {
        let (code, err) = run(extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(
            err.contains(needle),
            "{extra:?}: expected '{needle}' in: {err}"
        );
    }
    assert!(!d.join("w.zarr").exists(), "a refused run leaves no array");
    std::fs::write(d.join("v.zarr/zarr.json"), "[]").unwrap();
    let (code, err) = run(&["-o", "v.zarr", "--chunk", "8", "--resume"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("not an array this program can write into"),
        "{err}"
    );
    let (code, err) = run(&["-o", "v.zarr", "--chunk", "8", "--force", "--gzip"]);
    assert_eq!(code, 0, "{err}");
    let a = ZarrArray::open(&d.join("v.zarr")).unwrap();
    assert_eq!(a.spec().codec, Codec::Gzip(1));
    assert_close(&a.read_all().unwrap(), &npy, tol, "cli gzip zarr vs npy");
}
