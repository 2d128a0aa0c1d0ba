//! Lidar input (issue 12): LAS/LAZ reading, recentring, filters, colours, errors. The
//! expectations are computed here from the raw records, read with the `las` crate
//! directly, never copied from the reader's output. Tests skip (with a printed reason)
//! when data/ is absent.

mod common;

use common::data_file;
use glam::DVec3;
use smoothtrace::colour::SetColours;
use smoothtrace::eval::EvalParams;
use smoothtrace::eval::colour::colour_at;
use smoothtrace::las::{self, ColorBy, LasFilters, LasOptions, Returns, Thin};
use smoothtrace::mesh::{Mesh, MeshError};
use smoothtrace::primitives::{AnySet, PrimitiveKind};
use smoothtrace::rgb::{self as colour, Colormap, palette, srgb8_to_linear};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// One raw record's fields, straight from the `las` crate.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Raw {
    p: DVec3,
    intensity: u16,
    class: u8,
    return_number: u8,
    number_of_returns: u8,
    rgb: Option<[u16; 3]>,
}

fn raw_records(path: &Path) -> (::las::Header, Vec<Raw>) {
    let mut reader = ::las::Reader::from_path(path).unwrap();
    let header = reader.header().clone();
    let data = reader.read_all().unwrap();
    let records = data
        .points()
        .map(|p| p.unwrap())
        .map(|p| Raw {
            p: DVec3::new(p.x, p.y, p.z),
            intensity: p.intensity,
            class: u8::from(p.classification),
            return_number: p.return_number,
            number_of_returns: p.number_of_returns,
            rgb: p.color.map(|c| [c.red, c.green, c.blue]),
        })
        .collect();
    (header, records)
}

fn bounds_of<'a>(points: impl IntoIterator<Item = &'a Raw>) -> [DVec3; 2] {
    points.into_iter().fold(
        [DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)],
        |[lo, hi], r| [lo.min(r.p), hi.max(r.p)],
    )
}

/// Options that keep every record (no noise exclusion).
fn keep_all() -> LasOptions {
    LasOptions {
        filters: LasFilters {
            exclude_classes: Vec::new(),
            ..Default::default()
        },
        ..Default::default()
    }
}

fn trim_files() -> Option<[PathBuf; 3]> {
    Some([
        data_file("las/autzen_trim.las")?,
        data_file("las/autzen_trim.laz")?,
        data_file("las/autzen_trim_7.las")?,
    ])
}

#[test]
fn trim_files_agree_with_each_other_and_with_their_headers() {
    let Some(files) = trim_files() else { return };
    let raws: Vec<(::las::Header, Vec<Raw>)> = files.iter().map(|f| raw_records(f)).collect();
    for (f, (header, records)) in files.iter().zip(&raws) {
        assert_eq!(records.len() as u64, header.number_of_points(), "{f:?}");
        // The header's box is the records' box, up to its stated precision (the scale).
        let [lo, hi] = bounds_of(records);
        let hb = header.bounds();
        let scale = header.transforms().x.scale;
        for (a, b) in [
            (lo, DVec3::new(hb.min.x, hb.min.y, hb.min.z)),
            (hi, DVec3::new(hb.max.x, hb.max.y, hb.max.z)),
        ] {
            assert!(
                (a - b).abs().max_element() <= scale,
                "{f:?}: {a} vs header {b}"
            );
        }
    }
    // LAZ decompresses to exactly the LAS records; the LAS 1.4 format 7 copy holds the
    // same points and attributes.
    assert_eq!(raws[0].1, raws[1].1, "LAS and LAZ records differ");
    assert_eq!(raws[0].1, raws[2].1, "format 3 and format 7 records differ");
    assert_eq!(raws[2].0.point_format().to_u8().unwrap(), 7);
    // Our reader: every point, the same f32 vertices for all three files.
    let clouds: Vec<las::LasCloud> = files
        .iter()
        .map(|f| las::read(f, &keep_all()).unwrap())
        .collect();
    for c in &clouds {
        assert_eq!(c.mesh.vertices.len(), raws[0].1.len());
        assert_eq!(c.header_points, raws[0].1.len() as u64);
        assert!(c.mesh.segments.is_empty() && c.mesh.triangles.is_empty());
    }
    assert_eq!(clouds[0].mesh.vertices, clouds[1].mesh.vertices);
    assert_eq!(clouds[0].mesh.vertices, clouds[2].mesh.vertices);
    assert_eq!(clouds[0].version, "1.2");
    assert_eq!(clouds[2].version, "1.4");
}

#[test]
fn recentring_keeps_file_coordinates_exact() {
    let Some(files) = trim_files() else { return };
    let (header, records) = raw_records(&files[1]);
    let cloud = las::read(&files[1], &keep_all()).unwrap();
    let hb = header.bounds();
    let header_centre =
        0.5 * (DVec3::new(hb.min.x, hb.min.y, hb.min.z) + DVec3::new(hb.max.x, hb.max.y, hb.max.z));
    assert_eq!(cloud.origin, header_centre);
    // Reported bounds: exact file coordinates, to 1e-9 relative (they are in fact equal).
    let [lo, hi] = bounds_of(&records);
    for (got, want) in [(cloud.bounds[0], lo), (cloud.bounds[1], hi)] {
        let rel = ((got - want).abs() / want.abs()).max_element();
        assert!(
            rel <= 1e-9,
            "bounds {got} vs records {want}: relative {rel:e}"
        );
    }
    // Every stored vertex, put back in file coordinates, is within 1e-9 of its record
    // relative to the coordinates' magnitude; storing the file coordinates in f32
    // directly would not be.
    let mut worst_recentred: f64 = 0.0;
    let mut worst_plain: f64 = 0.0;
    for (v, r) in cloud.mesh.vertices.iter().zip(&records) {
        let back = v.as_dvec3() + cloud.origin;
        worst_recentred = worst_recentred.max((back - r.p).length() / r.p.length());
        let plain = r.p.as_vec3().as_dvec3();
        worst_plain = worst_plain.max((plain - r.p).length() / r.p.length());
    }
    assert!(worst_recentred <= 1e-9, "recentred: {worst_recentred:e}");
    assert!(
        worst_plain > 1e-9,
        "plain f32 would be exact too: {worst_plain:e}"
    );
}

/// The points `filters` must keep, computed from the raw records by brute force.
fn expected(records: &[Raw], f: &LasFilters) -> Vec<Raw> {
    let mut kept: Vec<Raw> = records
        .iter()
        .filter(|r| f.classes.as_ref().is_none_or(|c| c.contains(&r.class)))
        .filter(|r| !f.exclude_classes.contains(&r.class))
        .filter(|r| match f.returns {
            Returns::All => true,
            Returns::First => r.return_number == 1,
            Returns::Last => r.return_number == r.number_of_returns,
        })
        .filter(|r| {
            f.crop
                .is_none_or(|[lo, hi]| r.p.cmpge(lo).all() && r.p.cmple(hi).all())
        })
        .copied()
        .collect();
    match f.thin {
        Some(Thin::Every(k)) => kept = kept.into_iter().step_by(k as usize).collect(),
        Some(Thin::Voxel(v)) => {
            // One per occupied voxel: the one nearest the centre, the first on a tie.
            let cell = |p: DVec3| (p / v).floor();
            let mut best: Vec<(i64, i64, i64, usize)> = Vec::new();
            let mut seen = std::collections::HashMap::new();
            for (i, r) in kept.iter().enumerate() {
                let c = cell(r.p);
                let key = (c.x as i64, c.y as i64, c.z as i64);
                let d2 = (r.p - (c + 0.5) * v).length_squared();
                let e = seen.entry(key).or_insert((i, d2));
                if d2 < e.1 {
                    *e = (i, d2);
                }
            }
            best.extend(seen.iter().map(|(k, (i, _))| (k.0, k.1, k.2, *i)));
            let keep: HashSet<usize> = best.iter().map(|b| b.3).collect();
            kept = kept
                .into_iter()
                .enumerate()
                .filter(|(i, _)| keep.contains(i))
                .map(|(_, r)| r)
                .collect();
        }
        None => {}
    }
    kept
}

#[test]
fn filters_keep_what_the_raw_records_say() {
    let Some(files) = trim_files() else { return };
    let (header, records) = raw_records(&files[1]);
    let hb = header.bounds();
    let (lo, hi) = (
        DVec3::new(hb.min.x, hb.min.y, hb.min.z),
        DVec3::new(hb.max.x, hb.max.y, hb.max.z),
    );
    let quarter = 0.25 * (hi - lo);
    let cases = [
        LasFilters::default(),
        LasFilters {
            classes: Some(vec![2, 6]),
            exclude_classes: Vec::new(),
            ..Default::default()
        },
        LasFilters {
            exclude_classes: vec![1, 7, 18],
            returns: Returns::First,
            ..Default::default()
        },
        LasFilters {
            returns: Returns::Last,
            crop: Some([lo + quarter, hi - quarter]),
            ..Default::default()
        },
        LasFilters {
            thin: Some(Thin::Every(3)),
            ..Default::default()
        },
        LasFilters {
            classes: Some(vec![2]),
            exclude_classes: Vec::new(),
            thin: Some(Thin::Voxel(10.0)),
            ..Default::default()
        },
    ];
    for f in cases {
        let want = expected(&records, &f);
        assert!(!want.is_empty() && want.len() < records.len() || f == LasFilters::default());
        let options = LasOptions {
            filters: f.clone(),
            ..Default::default()
        };
        // The LAS and the LAZ copy give the same result.
        for file in &files[..2] {
            let cloud = las::read(file, &options).unwrap();
            assert_eq!(cloud.mesh.vertices.len(), want.len(), "{f:?} on {file:?}");
            assert_eq!(cloud.counts.first().unwrap().kept, records.len() as u64);
            assert_eq!(
                cloud.counts.last().unwrap().kept,
                want.len() as u64,
                "{f:?}"
            );
            for (v, r) in cloud.mesh.vertices.iter().zip(&want) {
                let back = v.as_dvec3() + cloud.origin;
                assert!(
                    (back - r.p).abs().max_element() < 1e-3,
                    "{f:?}: {back} vs {}",
                    r.p
                );
            }
            assert_eq!(cloud.bounds, bounds_of(&want), "{f:?}");
        }
    }
    // The default drops the noise classes, and says so in its counts.
    let cloud = las::read(&files[1], &LasOptions::default()).unwrap();
    let noise = records
        .iter()
        .filter(|r| [7, 18].contains(&r.class))
        .count();
    assert_eq!(cloud.mesh.vertices.len(), records.len() - noise);
    assert_eq!(cloud.counts[1].filter, "exclude_classes = [7, 18]");
}

#[test]
fn colours_follow_the_attributes() {
    let Some(files) = trim_files() else { return };
    let (_, records) = raw_records(&files[1]);
    let read = |by: ColorBy, colormap: Option<Colormap>| {
        let options = LasOptions {
            color_by: Some(by),
            colormap,
            ..keep_all()
        };
        las::read(&files[1], &options).unwrap().colours.unwrap()
    };
    let by_class = read(ColorBy::Classification, None);
    for (c, r) in by_class.iter().zip(&records) {
        assert_eq!(*c, srgb8_to_linear(palette::class_colour(r.class)));
    }
    // RGB: 16-bit channels when any exceeds 255, scaled by 1/257 to 8 bits.
    let rgb: Vec<[u16; 3]> = records.iter().map(|r| r.rgb.unwrap()).collect();
    let sixteen = rgb.iter().flatten().any(|&c| c > 255);
    let by_rgb = read(ColorBy::Rgb, None);
    for (c, v) in by_rgb.iter().zip(&rgb) {
        let eight = v.map(|x| {
            if sixteen {
                (x as f64 / 257.0).round() as u8
            } else {
                x as u8
            }
        });
        assert_eq!(*c, srgb8_to_linear(eight));
    }
    // Elevation: the lowest point at the colormap's start, the highest at its end.
    let by_z = read(ColorBy::Elevation, Some(Colormap::Magma));
    let (imin, imax) = (0..records.len()).fold((0, 0), |(a, b), i| {
        let z = records[i].p.z;
        (
            if z < records[a].p.z { i } else { a },
            if z > records[b].p.z { i } else { b },
        )
    });
    assert_eq!(by_z[imin], srgb8_to_linear(Colormap::Magma.srgb8(0.0)));
    assert_eq!(by_z[imax], srgb8_to_linear(Colormap::Magma.srgb8(1.0)));
    // A format without RGB cannot be coloured by it: the error names the file and key.
    if let Some(no_rgb) = data_file("las/simple.laz") {
        let fmt = ::las::Reader::from_path(&no_rgb)
            .unwrap()
            .header()
            .point_format()
            .has_color;
        let r = las::read(
            &no_rgb,
            &LasOptions {
                color_by: Some(ColorBy::Rgb),
                ..Default::default()
            },
        );
        if fmt {
            assert!(r.is_ok());
        } else {
            let e = r.unwrap_err().to_string();
            assert!(e.contains("simple.laz") && e.contains("color_by"), "{e}");
        }
    }
}

fn expect_file_error(path: &Path, name: &str) -> String {
    let e = las::read(path, &LasOptions::default()).unwrap_err();
    assert!(matches!(e, MeshError::Format { .. } | MeshError::Io { .. }));
    let m = e.to_string();
    assert!(m.contains(name), "error does not name {name}: {m}");
    // The mesh loader (query, field, scenes) gives the same error.
    let m2 = smoothtrace::load::load_mesh(path).unwrap_err().to_string();
    assert!(m2.contains(name), "{m2}");
    m
}

#[test]
fn corrupt_and_truncated_files_are_clear_errors() {
    let Some(garbage) = data_file("las/garbage_nVariableLength.las") else {
        return;
    };
    expect_file_error(&garbage, "garbage_nVariableLength.las");
    let Some(files) = trim_files() else { return };
    let dir = tempfile::tempdir().unwrap();
    for (source, keep) in [
        (&files[1], 0.5),
        (&files[1], 0.98),
        (&files[1], 0.01),
        (&files[0], 0.5),
        (&files[0], 0.999),
    ] {
        let bytes = std::fs::read(source).unwrap();
        let cut = (bytes.len() as f64 * keep) as usize;
        let ext = source.extension().unwrap().to_str().unwrap();
        let name = format!("cut_{}_{cut}.{ext}", (keep * 1000.0) as u32);
        let path = dir.path().join(&name);
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let m = expect_file_error(&path, &name);
        assert!(!m.contains("panicked"), "{m}");
    }
}

/// Regression for the abort `mutated_laz_never_panics` found: a LAZ chunk table whose
/// chunk count (or offset) is corrupt is refused, naming the file, before the decoder
/// reserves memory for it.
#[test]
fn laz_chunk_table_counts_beyond_the_file_are_errors_not_aborts() {
    let Some(seed) = data_file("las/simple.laz") else {
        return;
    };
    let bytes = std::fs::read(&seed).unwrap();
    let data_start = u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize;
    let table = i64::from_le_bytes(bytes[data_start..data_start + 8].try_into().unwrap());
    assert!(
        table as usize > data_start && (table as usize) < bytes.len(),
        "{table}"
    );
    let table = table as usize;
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<(&str, Vec<u8>, &str)> = Vec::new();
    for count in [u32::MAX, 1 << 20] {
        let mut b = bytes.clone();
        b[table + 4..table + 8].copy_from_slice(&count.to_le_bytes());
        cases.push(("chunks", b, "chunks, but the"));
    }
    let mut b = bytes.clone();
    b[data_start..data_start + 8].copy_from_slice(&(bytes.len() as i64 * 4).to_le_bytes());
    cases.push(("offset", b, "beyond the end"));
    for (i, (what, b, want)) in cases.into_iter().enumerate() {
        let name = format!("bad_{what}_{i}.laz");
        let path = dir.path().join(&name);
        std::fs::write(&path, b).unwrap();
        let m = expect_file_error(&path, &name);
        assert!(m.contains(want), "{m}");
    }
    // The unchanged file still reads.
    let path = dir.path().join("same.laz");
    std::fs::write(&path, &bytes).unwrap();
    assert!(las::read(&path, &keep_all()).is_ok());
}

#[test]
fn lidar_gives_points_only() {
    let Some(laz) = data_file("las/autzen_trim.laz") else {
        return;
    };
    for kind in [PrimitiveKind::Edges, PrimitiveKind::Triangles] {
        let e = smoothtrace::load::load_with_origin(&laz, &[PrimitiveKind::Points, kind])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("autzen_trim.laz") && e.contains("points only") && e.contains(kind.name()),
            "{e}"
        );
    }
    let (mesh, origin) =
        smoothtrace::load::load_with_origin(&laz, &[PrimitiveKind::Points]).unwrap();
    assert!(!mesh.vertices.is_empty() && origin.x > 6e5);
    // In a scene: the primitives key is named, with its line.
    let text = format!(
        "[camera]\norigin = [0, 0, 900]\ntarget = [0, 0, 0]\n\n[[object]]\nmesh = {:?}\n\
         primitives = [\"points\", \"triangles\"]\nalpha = 1.0\n",
        laz.to_str().unwrap()
    );
    let e = smoothtrace::scene::Scene::from_str(&text, Path::new("lidar.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("lidar.toml:7:")
            && e.contains("object[0].primitives")
            && e.contains("points only"),
        "{e}"
    );
}

#[test]
fn two_coloured_points_blend_halfway_and_keep_their_own_colour() {
    let mesh = Mesh {
        vertices: vec![glam::Vec3::ZERO, glam::Vec3::X],
        name: "two".into(),
        ..Default::default()
    };
    let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
    let (red, blue) = ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let cols = SetColours::build(&set, &mesh, &[red, blue]);
    let p = EvalParams::new(60.0, 60.0, 0.0);
    let at = |x: f64| colour_at(&[&set], &[&cols], DVec3::new(x, 0.3, 0.0), &p).unwrap();
    let mid = at(0.5);
    for (m, want) in mid.iter().zip([0.5, 0.0, 0.5]) {
        assert!((m - want).abs() < 1e-6, "halfway: {mid:?}");
    }
    // At each point the other's weight is exp(-60) of its own.
    let near = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
    assert!(near(
        colour_at(&[&set], &[&cols], DVec3::ZERO, &p).unwrap(),
        red
    ));
    assert!(near(
        colour_at(&[&set], &[&cols], DVec3::X, &p).unwrap(),
        blue
    ));
    // In between, the blend is the softmax of the distances (brute force).
    for x in [0.2, 0.45, 0.7] {
        let q = DVec3::new(x, 0.3, 0.0);
        let (w0, w1) = (
            (-60.0 * q.length()).exp(),
            (-60.0 * (q - DVec3::X).length()).exp(),
        );
        let t = (w1 / (w0 + w1)) as f32;
        let got = at(x);
        assert!(
            (got[0] - (1.0 - t)).abs() < 1e-6 && (got[2] - t).abs() < 1e-6,
            "{x}: {got:?}"
        );
    }
}

#[test]
fn colour_field_matches_brute_force_softmax() {
    let mut rng = common::Rng::new(12);
    let n = 3000;
    let vertices: Vec<glam::Vec3> = (0..n).map(|_| rng.vec().as_vec3()).collect();
    let colours: Vec<colour::Linear> = (0..n)
        .map(|_| {
            [
                rng.next_f64() as f32,
                rng.next_f64() as f32,
                rng.next_f64() as f32,
            ]
        })
        .collect();
    let mesh = Mesh {
        vertices: vertices.clone(),
        name: "random".into(),
        ..Default::default()
    };
    let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
    let cols = SetColours::build(&set, &mesh, &colours);
    // Node means: the root's mean is the mean of all colours.
    let mean: Vec<f64> = (0..3)
        .map(|j| colours.iter().map(|c| c[j] as f64).sum::<f64>() / n as f64)
        .collect();
    for (root, mean) in cols.nodes[0].iter().zip(&mean) {
        assert!(
            (*root as f64 - mean).abs() < 1e-5,
            "root mean {root} vs {mean}"
        );
    }
    for alpha in [5.0, 40.0] {
        let p = EvalParams::new(alpha, alpha, 0.0);
        for _ in 0..50 {
            let x = rng.vec() * 1.2;
            let got = colour_at(&[&set], &[&cols], x, &p).unwrap();
            let d: Vec<f64> = vertices
                .iter()
                .map(|v| (x - v.as_dvec3()).length())
                .collect();
            let m = d.iter().copied().fold(f64::INFINITY, f64::min);
            let w: Vec<f64> = d.iter().map(|d| (-alpha * (d - m)).exp()).collect();
            let s: f64 = w.iter().sum();
            for j in 0..3 {
                let want: f64 = w
                    .iter()
                    .zip(&colours)
                    .map(|(w, c)| w * c[j] as f64)
                    .sum::<f64>()
                    / s;
                assert!(
                    (got[j] as f64 - want).abs() < 1e-5,
                    "alpha {alpha} at {x}: channel {j} {} vs brute force {want}",
                    got[j]
                );
            }
        }
    }
}

/// A scene around `object` (extra lines of an `[[object]]` table) with `mesh`.
fn scene_text(mesh: &Path, object: &str) -> String {
    format!(
        "[camera]\norigin = [0, 300, 500]\ntarget = [0, 0, 0]\n\n[image]\nwidth = 64\nheight = 36\n\n\
         [[object]]\nmesh = {:?}\nprimitives = \"points\"\nalpha = 0.3\n{object}",
        mesh.to_str().unwrap()
    )
}

fn scene_error(mesh: &Path, object: &str) -> String {
    smoothtrace::scene::Scene::from_str(&scene_text(mesh, object), Path::new("s.toml"))
        .unwrap_err()
        .to_string()
}

#[test]
fn scene_keys_resolve_and_bad_values_are_named() {
    // Files are checked to exist only, so an empty .las and an .obj serve here.
    let dir = tempfile::tempdir().unwrap();
    let las_path = dir.path().join("t.las");
    let obj_path = dir.path().join("t.obj");
    std::fs::write(&las_path, "").unwrap();
    std::fs::write(&obj_path, "v 0 0 0\n").unwrap();
    let good = "classes = [2, 6]\nreturns = \"first\"\ncolor_by = \"elevation\"\n\
                colormap = \"turbo\"\norigin = [1, 2, 3]\n\
                crop = { min = [0, 0, 0], max = [10, 10, 10] }\nthin = { voxel = 2.5 }\n";
    let s = smoothtrace::scene::Scene::from_str(&scene_text(&las_path, good), Path::new("s.toml"))
        .unwrap();
    let o = &s.objects[0].las;
    assert_eq!(o.filters.classes, Some(vec![2, 6]));
    assert!(
        o.filters.exclude_classes.is_empty(),
        "classes replace the noise default"
    );
    assert_eq!(o.filters.returns, Returns::First);
    assert_eq!(o.filters.thin, Some(Thin::Voxel(2.5)));
    assert_eq!(o.color_by, Some(ColorBy::Elevation));
    assert_eq!(o.colormap, Some(Colormap::Turbo));
    assert_eq!(o.origin, Some(DVec3::new(1.0, 2.0, 3.0)));
    let s = smoothtrace::scene::Scene::from_str(&scene_text(&las_path, ""), Path::new("s.toml"))
        .unwrap();
    assert_eq!(s.objects[0].las, LasOptions::default());
    assert_eq!(s.objects[0].las.filters.exclude_classes, [7, 18]);
    // Each bad value: the message has the place and the key.
    for (lines, needles) in [
        (
            "classes = [2, 300]",
            &["s.toml:13:", "object[0].classes", "0..=255"][..],
        ),
        (
            "returns = \"second\"",
            &["s.toml:13:", "object[0].returns", "\"first\""],
        ),
        (
            "color_by = \"altitude\"",
            &["s.toml:13:", "object[0].color_by", "\"rgb\""],
        ),
        (
            "color_by = \"intensity\"\ncolormap = \"jet\"",
            &[
                "s.toml:14:",
                "object[0].colormap",
                "unknown colormap",
                "\"jet\"",
                "viridis",
            ],
        ),
        (
            "color_by = \"rgb\"\ncolormap = \"magma\"",
            &["s.toml:14:", "object[0].colormap", "intensity"],
        ),
        (
            "thin = { voxel = 0.0 }",
            &["s.toml:13:", "object[0].thin.voxel", "> 0"],
        ),
        (
            "thin = { voxel = 1.0, every = 2 }",
            &["s.toml:13:", "exactly one of voxel"],
        ),
        (
            "thin = { every = 0 }",
            &["s.toml:13:", "every must be an integer >= 1"],
        ),
        (
            "crop = { min = [0, 0, 5], max = [1, 1, 1] }",
            &["s.toml:13:", "min <= max"],
        ),
        (
            "crop = { min = [0, 0, 0], maks = [1, 1, 1] }",
            &["s.toml:13:", "maks"],
        ),
    ] {
        let e = scene_error(&las_path, lines);
        for n in needles {
            assert!(e.contains(n), "{lines}: message lacks `{n}`: {e}");
        }
    }
    // Lidar keys on a mesh that is not lidar.
    for key in [
        "classes = [2]",
        "color_by = \"rgb\"",
        "thin = { every = 2 }",
    ] {
        let e = scene_error(&obj_path, key);
        let name = key.split(' ').next().unwrap();
        assert!(
            e.contains("s.toml:13:")
                && e.contains(&format!("object[0].{name}"))
                && e.contains("lidar"),
            "{key}: {e}"
        );
    }
}

#[test]
fn a_single_class_renders_in_its_palette_hue() {
    let Some(laz) = data_file("las/autzen_trim.laz") else {
        return;
    };
    let text = scene_text(
        &laz,
        "classes = [2]\ncolor_by = \"classification\"\n[object.transform]\nrotate = [-90, 0, 0]\n",
    );
    let scene = smoothtrace::scene::Scene::from_str(&text, Path::new("s.toml")).unwrap();
    let (built, rendered) =
        smoothtrace::render::pipeline::render_scene(&scene, |o| o, &|_| {}).unwrap();
    assert!(built.objects[0].colours.is_some());
    // Every point is ground (#aa5500), so the colour field is that colour everywhere
    // and each hit pixel is it, scaled by the MatCap's light: red > green > blue = 0
    // with green / red as in the palette's linear colour.
    let ground = srgb8_to_linear(palette::class_colour(2));
    let mut hits = 0;
    for (px, d) in rendered.image.pixels().zip(&rendered.depth) {
        if !d.is_finite() {
            continue;
        }
        hits += 1;
        let lin = srgb8_to_linear(px.0);
        assert_eq!(px.0[2], 0, "{px:?}");
        if px.0[0] > 60 {
            let ratio = lin[1] / lin[0];
            let want = ground[1] / ground[0];
            assert!(
                (ratio - want).abs() < 0.05,
                "{px:?}: green/red {ratio} vs {want}"
            );
        }
    }
    assert!(hits > 100, "only {hits} hits");
}

#[test]
fn query_takes_points_in_file_coordinates() {
    let Some(laz) = data_file("las/autzen_trim.laz") else {
        return;
    };
    let (_, records) = raw_records(&laz);
    let ground = records.iter().find(|r| r.class == 2).unwrap();
    let line = format!("{} {} {}\n", ground.p.x, ground.p.y, ground.p.z + 2.0);
    let run = |primitive: &str| {
        use std::io::Write;
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
            .args([
                "query",
                laz.to_str().unwrap(),
                "-p",
                primitive,
                "--alpha",
                "1",
            ])
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let _ = child.stdin.take().unwrap().write_all(line.as_bytes());
        child.wait_with_output().unwrap()
    };
    let out = run("points");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cols: Vec<f64> = String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect();
    // The exact distance (5th column) to the cloud is at most the 2 ft to that point,
    // and the nearest point of all the records (noise excluded) is that far: brute force.
    let q = ground.p + DVec3::new(0.0, 0.0, 2.0);
    let want = records
        .iter()
        .filter(|r| ![7, 18].contains(&r.class))
        .map(|r| (r.p - q).length())
        .fold(f64::INFINITY, f64::min);
    assert!(
        (cols[4] - want).abs() < 1e-3,
        "distance {} vs brute force {want}",
        cols[4]
    );
    let out = run("triangles");
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(
        e.contains("autzen_trim.laz") && e.contains("points only"),
        "{e}"
    );
}

#[test]
fn the_small_files_read_like_their_raw_records() {
    for name in [
        "1.2-with-color.las",
        "100-points.las",
        "extrabytes.las",
        "test1_4.las",
        "simple.laz",
    ] {
        let Some(path) = data_file(&format!("las/{name}")) else {
            return;
        };
        let (header, records) = raw_records(&path);
        let cloud = las::read(&path, &keep_all()).unwrap();
        assert_eq!(cloud.header_points, header.number_of_points(), "{name}");
        assert_eq!(cloud.mesh.vertices.len(), records.len(), "{name}");
        assert_eq!(cloud.bounds, bounds_of(&records), "{name}");
        assert_eq!(
            cloud.point_format,
            header.point_format().to_u8().unwrap(),
            "{name}"
        );
    }
}

#[test]
fn noise_is_dropped_by_default_and_kept_on_request() {
    // A file written here: classes 1, 2, 7, 18 at known places.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("noise.las");
    let classes = [1u8, 2, 7, 18, 2, 7];
    {
        let mut builder = ::las::Builder::from((1, 4));
        builder.point_format = ::las::point::Format::new(6).unwrap();
        let mut w = ::las::Writer::from_path(&path, builder.into_header().unwrap()).unwrap();
        for (i, &c) in classes.iter().enumerate() {
            w.write_point(::las::Point {
                x: 1000.0 + i as f64,
                y: 2000.0,
                z: 10.0 * i as f64,
                classification: ::las::point::Classification::new(c).unwrap(),
                return_number: 1,
                number_of_returns: 1,
                gps_time: Some(0.0),
                ..Default::default()
            })
            .unwrap();
        }
        w.close().unwrap();
    }
    let kept = |options: &LasOptions| {
        let c = las::read(&path, options).unwrap();
        c.mesh
            .vertices
            .iter()
            .map(|v| ((v.as_dvec3() + c.origin).x - 1000.0).round() as usize)
            .collect::<Vec<_>>()
    };
    let noise_free: Vec<usize> = (0..classes.len())
        .filter(|&i| ![7, 18].contains(&classes[i]))
        .collect();
    assert_eq!(kept(&LasOptions::default()), noise_free);
    assert_eq!(kept(&keep_all()), (0..classes.len()).collect::<Vec<_>>());
    // Naming classes replaces the default exclusion (as a scene does).
    let only_noise = LasOptions {
        filters: LasFilters {
            classes: Some(vec![7]),
            exclude_classes: Vec::new(),
            ..Default::default()
        },
        ..Default::default()
    };
    assert_eq!(kept(&only_noise), [2, 5]);
}
