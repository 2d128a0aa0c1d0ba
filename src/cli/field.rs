//! `smoothtrace field`: an exact (or smooth) distance field on a voxel grid, written as
//! `.npy` (f32, shape `(NZ, NY, NX)`), with an optional PNG montage of slices, or as a
//! chunked Zarr array written chunk by chunk (`zarr`).

mod zarr;

use super::console::note;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use glam::DVec3;
use smoothtrace::field::{self, Domains, FieldOptions, Grid, Method};
use smoothtrace::output::{IMAGE_8BIT, Kind, Output};
use smoothtrace::primitives::PrimitiveKind;
use std::path::PathBuf;

/// Exact methods selectable with `--method`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Slice-by-slice linear factorization (Sud et al. 2006).
    Linfac,
    /// One exact nearest-primitive query per voxel on the BVH.
    Bvh,
    /// Every primitive at every voxel (small inputs only).
    Brute,
}

#[derive(Args, Debug)]
pub struct FieldArgs {
    /// Mesh file (.obj, .ply, .stl), or a lidar point cloud (.las, .laz; --bounds in its
    /// file coordinates).
    mesh: PathBuf,
    /// Primitive set: points (all vertices), edges (segments, else triangle edges) or
    /// triangles.
    #[arg(long, short)]
    primitive: PrimitiveKind,
    /// Voxels along the longest axis of the bounds; cubic voxels, the other axes rounded
    /// up (their extent grows symmetrically to a whole number of voxels).
    #[arg(long, conflicts_with = "res_xyz", required_unless_present = "res_xyz")]
    res: Option<usize>,
    /// Explicit voxel counts along x, y and z (the bounds are kept as given).
    #[arg(long, num_args = 3, value_names = ["NX", "NY", "NZ"])]
    res_xyz: Option<Vec<usize>>,
    /// Grid bounds (default: the mesh's bounding box grown by 10% of its diagonal on
    /// every side).
    #[arg(long, num_args = 6, allow_negative_numbers = true,
          value_names = ["XMIN", "YMIN", "ZMIN", "XMAX", "YMAX", "ZMAX"])]
    bounds: Option<Vec<f64>>,
    /// Narrow band: exact distances where d <= D, +inf elsewhere (exact methods only).
    #[arg(long, value_name = "D")]
    band: Option<f64>,
    /// Exact method.
    #[arg(long, value_enum, default_value_t = MethodArg::Linfac)]
    method: MethodArg,
    /// Linfac domains: tight (prisms, wedges, polar cones; any topology) or loose
    /// (prisms, slabs, whole slices for vertices).
    #[arg(long, value_enum, default_value_t = Domains::Tight)]
    domains: Domains,
    /// Linfac: do not cut polygons to the tiles they can win (per-tile distance bounds
    /// from nearest queries at tile centres).
    #[arg(long)]
    no_cull: bool,
    /// Store the smooth distance (SPEC 2) instead of the exact one; needs --alpha.
    #[arg(long, requires = "alpha")]
    smooth: bool,
    /// Smooth distance sharpness (1/length).
    #[arg(long, requires = "smooth")]
    alpha: Option<f64>,
    /// Weight attenuation threshold (default: alpha).
    #[arg(long, requires = "smooth")]
    max_alpha: Option<f64>,
    /// Barnes-Hut opening parameter in [0, 1].
    #[arg(long, requires = "smooth", default_value_t = 0.5)]
    beta: f64,
    /// Signed distances: negative inside the solid (fast winding number of the
    /// triangles above 1/2, evaluated only where the sign can change). Needs
    /// `--primitive triangles`.
    #[arg(long, conflicts_with = "smooth")]
    signed: bool,
    /// Far-field parameter of the fast winding number, in [0, 1) (0 = exact sum).
    #[arg(long, requires = "signed", default_value_t = smoothtrace::winding::DEFAULT_BETA)]
    winding_beta: f64,
    /// Output `.npy` file, or a `.zarr` folder: a chunked Zarr v3 array written chunk by
    /// chunk, so the volume need not fit in memory.
    #[arg(long, short)]
    output: PathBuf,
    /// .zarr: chunk edge in voxels (cubic chunks, cut to shorter axes; default 128, or
    /// the longest axis when it is shorter).
    #[arg(long, value_name = "N")]
    chunk: Option<usize>,
    /// .zarr: compute only chunks I..J-1 (C order over the chunk grid; either side may be
    /// left out; I alone is one chunk) into the array, creating it if it does not exist:
    /// one job of a job array.
    #[arg(long, value_name = "I:J")]
    chunks: Option<String>,
    /// .zarr: compute only the chunks missing from an existing array (after an
    /// interruption, or after the jobs of a job array).
    #[arg(long)]
    resume: bool,
    /// .zarr: replace an existing array (a folder with zarr.json, or an empty folder).
    #[arg(long, conflicts_with = "resume")]
    force: bool,
    /// .zarr: compress chunks with gzip (level 1): small for --band fields, about 11%
    /// smaller and slower to write for dense ones.
    #[arg(long)]
    gzip: bool,
    /// Also write a montage of a few z slices (.png, .jpg/.jpeg or .webp).
    #[arg(long, value_name = "IMAGE")]
    preview: Option<PathBuf>,
}

pub fn run(a: FieldArgs) -> Result<()> {
    // Outputs are checked before the work (issue 10, defects 5 and 7).
    let chunked = zarr::is_zarr(&a.output);
    if chunked {
        zarr::check_flags(&a)?;
    } else {
        Output::check(
            &a.output,
            &[Kind::Npy],
            "the distance field (or a .zarr array)",
        )?;
        zarr::refuse_flags(&a)?;
    }
    if let Some(p) = &a.preview {
        Output::check(p, IMAGE_8BIT, "the preview")?;
    }
    if a.signed {
        if a.primitive != PrimitiveKind::Triangles {
            bail!(
                "--signed takes the sign from the triangles' winding number; use --primitive triangles"
            );
        }
        smoothtrace::api::signed::check_beta("--winding-beta", a.winding_beta)?;
    }
    let (mesh, origin) = smoothtrace::load::load_with_origin(&a.mesh, &[a.primitive])?;
    if origin != DVec3::ZERO {
        note!(
            "{}: lidar points recentred: grid coordinates are file coordinates minus [{}, {}, {}]",
            a.mesh.display(),
            origin.x,
            origin.y,
            origin.z
        );
    }
    let (min, max) = match &a.bounds {
        Some(b) => (
            DVec3::new(b[0], b[1], b[2]) - origin,
            DVec3::new(b[3], b[4], b[5]) - origin,
        ),
        None => Grid::default_bounds(mesh.bounds())
            .context("cannot choose default bounds; give --bounds")?,
    };
    let grid = match (a.res, &a.res_xyz) {
        (_, Some(r)) => Grid::new(min, max, [r[0], r[1], r[2]])?,
        (Some(n), None) => Grid::cubic(min, max, n)?,
        (None, None) => bail!("give --res N or --res-xyz NX NY NZ"),
    };
    let method = if a.smooth {
        if a.method != MethodArg::Linfac {
            bail!("--smooth computes the smooth distance per voxel; drop --method");
        }
        let alpha = a.alpha.context("--smooth needs --alpha")?;
        Method::Smooth {
            alpha,
            max_alpha: a.max_alpha.unwrap_or(alpha),
            beta: a.beta,
        }
    } else {
        match a.method {
            MethodArg::Linfac => Method::Linfac,
            MethodArg::Bvh => Method::Bvh,
            MethodArg::Brute => Method::Brute,
        }
    };
    let options = FieldOptions {
        band: a.band,
        domains: a.domains,
        cull: !a.no_cull,
        memory_limit: None,
    };
    let h = grid.spacing();
    note!(
        "{}: {} {}, grid {} x {} x {} = {} voxels",
        a.mesh.display(),
        mesh.name,
        a.primitive,
        grid.res[0],
        grid.res[1],
        grid.res[2],
        grid.len()
    );
    note!(
        "  bounds [{}, {}, {}] .. [{}, {}, {}], spacing {} x {} x {}",
        grid.min.x,
        grid.min.y,
        grid.min.z,
        grid.max.x,
        grid.max.y,
        grid.max.z,
        h.x,
        h.y,
        h.z
    );
    if chunked {
        return zarr::run(&a, &mesh, &grid, method, &options);
    }
    let (mut f, s) = field::compute(&mesh, a.primitive, &grid, method, &options)?;
    let mut line = format!(
        "  {}: {:.3} s ({:.2} M voxels/s), setup {:.3} s",
        s.method,
        s.seconds,
        s.voxels_per_second * 1e-6,
        s.setup_seconds
    );
    if method == Method::Linfac {
        line += &format!(
            ", domains {:.3} s ({:.0}%), rasterization {:.3} s; {} sites ({} vertices, {} edges, {} faces), {:.2} evaluations per voxel",
            s.domain_seconds,
            100.0 * s.domain_share(),
            s.raster_seconds,
            s.sites,
            s.site_counts.vertices,
            s.site_counts.edges,
            s.site_counts.faces,
            s.evaluations_per_voxel()
        );
    } else {
        line += &format!(", {} primitives", s.sites);
    }
    note!("{line}");
    if a.signed {
        let st = field::sign::sign_field(&mesh, &mut f, a.winding_beta)?;
        note!(
            "  signed: {:.3} s (setup {:.3} s), {} block and {} voxel winding numbers ({:.2}% of the voxels), {} voxels inside{}",
            st.seconds,
            st.setup_seconds,
            st.block_evaluations,
            st.voxel_evaluations,
            100.0 * (st.block_evaluations + st.voxel_evaluations) as f64 / grid.len().max(1) as f64,
            st.inside,
            if st.boundary_edges == 0 {
                ", closed mesh".to_string()
            } else {
                format!(", open mesh ({} boundary edges)", st.boundary_edges)
            }
        );
    }
    if let Some(b) = a.band {
        let inside = f.values.iter().filter(|v| v.is_finite()).count();
        note!("  band {b}: {inside} voxels within it, the others hold +inf");
    }
    f.write_npy(&a.output)?;
    note!("  wrote {}", a.output.display());
    if let Some(p) = &a.preview {
        f.write_preview(p)?;
        note!("  wrote {}", p.display());
    }
    Ok(())
}
