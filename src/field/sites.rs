//! Sites and their domains for the linear-factorization method (SPEC 9).
//!
//! The primitive set is split into features whose closest point moves affinely with the
//! query: triangle interiors (faces), segment interiors (edges) and vertices. Each site
//! carries
//! - its distance function as an affine *distance vector* `D(p) = W (p - anchor)` with
//!   one row for a face (the unit normal), two for an edge (an orthonormal basis of the
//!   plane orthogonal to it) and three for a vertex (the identity), so `d(p) = |D(p)|`;
//! - its domain, a list of closed half-spaces `n . p <= c` (unit `n`) whose intersection
//!   contains every point whose closest feature of the whole set is this site.
//!
//! Domains. A site's *validity* constraints say where its distance function equals the
//! distance to the feature: the prism over a face (three planes through its edges along
//! its normal), the slab of a segment (two planes through its ends orthogonal to it); a
//! vertex is valid everywhere. The *tight* constraints come from first-order optimality:
//! if the closest point `c` of the whole set to `p` is on feature F and the set contains a
//! segment `[c, c + t]` (or a face containing `c` and `c + t`), then
//! `|p - c - e t|^2 >= |p - c|^2` for small `e > 0`, i.e. `(p - c) . t <= 0`. Hence
//! - an edge with incident faces `f_i` (any number: boundary, manifold, fins) lies in the
//!   intersection of the half-spaces `(p - a) . t_i <= 0`, where `t_i` is the in-face unit
//!   vector orthogonal to the edge pointing into `f_i`: for two faces this is the wedge
//!   bounded by the planes through the edge along the two face normals (Sud et al.);
//! - a vertex `v` with incident segments towards `w_j` lies in the polar cone
//!   `(p - v) . (w_j - v) <= 0` for all j. For a convex or concave vertex this is the
//!   cone of the incident face normals; for a saddle vertex whose edges positively span
//!   space it is `{v}` alone, which is exactly right (some incident edge is always closer).
//!   No manifoldness or orientation is assumed, so the tight domains are safe on
//!   non-manifold meshes, pinched vertices and triangle soups.
//!
//! The loose (non-manifold) domains of SPEC 9 drop the tight constraints: face prisms,
//! edge slabs, and the whole slice for a vertex.
//!
//! Robustness: every half-space is pushed outwards by a margin `eta` (1e-8 of the largest
//! voxel-to-mesh distance plus 1e-12 of the largest coordinate), so rounding in the
//! domain computation cannot drop a voxel from the domain of its closest feature. A face
//! or edge evaluated up to `eta` outside its validity region reports the distance to its
//! plane or line, which is below the true distance by at most `eta`, so the result is
//! exact to `eta`. Neighbouring domains overlap by `2 eta` along their common planes
//! (a prism's side plane is the wedge plane of the edge), which is what lets a face's
//! cross-section be bounded by its exact corners without the margin.
//!
//! Narrow band: with band `b` every domain is also limited to `d <= b`: the feature's
//! bounding box grown by `b` bounds the slices and the clipping rectangle, a face gets
//! the two planes `|n . (p - a)| <= b`, and the rasterizer cuts every row exactly to the
//! interval where the site's squared distance (a quadratic along the row) is `<= b^2`.
//!
//! Degenerate input: triangles that [`closest_on_triangle`](crate::geometry::closest)
//! treats as degenerate (squared sine of the largest angle below 1e-14) have
//! no face site (their distance is that of their edges, which are edge sites);
//! zero-length edges have no edge site (their end vertex is a site); a degenerate face
//! contributes no wedge constraint; a zero-length neighbour direction no cone constraint.

use crate::mesh::Mesh;
use crate::primitives::PrimitiveKind;
use glam::DVec3;

/// Which domains to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Domains {
    /// Face prisms, edge slabs cut by the wedge of their incident faces, vertex polar
    /// cones (safe for any topology, see the module docs).
    #[default]
    Tight,
    /// SPEC 9's non-manifold domains: face prisms, edge slabs, whole slices for vertices.
    Loose,
}

/// A closed half-space `n . p <= c` with unit `n` (margin included in `c`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HalfSpace {
    pub n: DVec3,
    pub c: f64,
}

/// The feature type of a site.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SiteKind {
    Vertex,
    Edge,
    Face,
}

/// One site: distance-vector rows, anchor, domain half-spaces, a point of its domain.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Site {
    pub kind: SiteKind,
    /// `D(p) = (rows[r] . (p - anchor))_r` for the first 1 (face), 2 (edge) or 3 (vertex)
    /// rows. A face's `anchor`, `rows[1]`, `rows[2]` are its three corners.
    pub anchor: DVec3,
    pub rows: [DVec3; 3],
    /// Range of this site's half-spaces in [`Sites::planes`].
    pub planes: (u32, u32),
    /// A point inside the domain (apex, edge midpoint, centroid): the z-range search
    /// starts there.
    pub witness: DVec3,
    /// Bounding box of the feature; grown by the band it bounds the banded domain.
    pub bounds: (DVec3, DVec3),
}

/// Number of sites of each kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SiteCounts {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
}

impl SiteCounts {
    pub fn total(&self) -> usize {
        self.vertices + self.edges + self.faces
    }
}

/// All sites of a primitive set with their domains.
#[derive(Clone, Debug, Default)]
pub(crate) struct Sites {
    pub sites: Vec<Site>,
    pub planes: Vec<HalfSpace>,
    pub counts: SiteCounts,
    /// Band plus margin: every site's distance is cut to it row by row; `None` without
    /// band.
    pub band: Option<f64>,
    /// The domain margin.
    pub eta: f64,
}

/// Builds the sites of `kind` from `mesh`. `eta` is the domain margin, `band` the
/// optional narrow band.
pub(crate) fn build_sites(
    mesh: &Mesh,
    kind: PrimitiveKind,
    domains: Domains,
    band: Option<f64>,
    eta: f64,
) -> Sites {
    let pos: Vec<DVec3> = mesh.vertices.iter().map(|v| v.as_dvec3()).collect();
    let mut b = Builder {
        out: Sites {
            band: band.map(|b| b + eta),
            eta,
            ..Sites::default()
        },
        band,
        eta,
    };
    let tight = domains == Domains::Tight;
    match kind {
        PrimitiveKind::Points => {
            for &p in &pos {
                b.vertex(p, &[]);
            }
        }
        PrimitiveKind::Edges => {
            let list = if mesh.segments.is_empty() {
                mesh.triangle_edges()
            } else {
                mesh.segments.clone()
            };
            let edges = unique_edges(list.iter().copied());
            for &[i, j] in &edges {
                b.edge(pos[i as usize], pos[j as usize], &[]);
            }
            let mut used = vec![false; pos.len()];
            for &[i, j] in &list {
                used[i as usize] = true;
                used[j as usize] = true;
            }
            b.vertices_of(&pos, &edges, &used, tight);
        }
        PrimitiveKind::Triangles => {
            let mut nondegenerate = vec![false; mesh.triangles.len()];
            for (f, t) in mesh.triangles.iter().enumerate() {
                let [p0, p1, p2] = t.map(|i| pos[i as usize]);
                if let Some(n) = face_normal(p0, p1, p2) {
                    nondegenerate[f] = true;
                    b.face(p0, p1, p2, n);
                }
            }
            // (edge key, third vertex of a non-degenerate incident face or u32::MAX).
            let mut inc: Vec<([u32; 2], u32)> = Vec::with_capacity(3 * mesh.triangles.len());
            for (f, t) in mesh.triangles.iter().enumerate() {
                for e in 0..3 {
                    let (i, j, o) = (t[e], t[(e + 1) % 3], t[(e + 2) % 3]);
                    if i == j {
                        continue;
                    }
                    let third = if nondegenerate[f] { o } else { u32::MAX };
                    inc.push(([i.min(j), i.max(j)], third));
                }
            }
            inc.sort_unstable();
            let mut edges = Vec::new();
            let mut thirds: Vec<DVec3> = Vec::new();
            let mut s = 0;
            while s < inc.len() {
                let key = inc[s].0;
                let mut e = s;
                thirds.clear();
                while e < inc.len() && inc[e].0 == key {
                    if tight && inc[e].1 != u32::MAX {
                        thirds.push(pos[inc[e].1 as usize]);
                    }
                    e += 1;
                }
                b.edge(pos[key[0] as usize], pos[key[1] as usize], &thirds);
                edges.push(key);
                s = e;
            }
            let mut used = vec![false; pos.len()];
            for t in &mesh.triangles {
                for &i in t {
                    used[i as usize] = true;
                }
            }
            b.vertices_of(&pos, &edges, &used, tight);
        }
    }
    b.out
}

/// Unit normal of a non-degenerate triangle (same test as `closest_on_triangle`).
fn face_normal(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    crate::geometry::closest::triangle_normal(a, b, c).map(|n| n / n.length())
}

/// Sorted unique undirected edges `[min, max]` without self-loops.
fn unique_edges(list: impl Iterator<Item = [u32; 2]>) -> Vec<[u32; 2]> {
    let mut v: Vec<[u32; 2]> = list
        .filter(|[a, b]| a != b)
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Two unit vectors completing `u` to an orthonormal basis.
fn orthonormal_pair(u: DVec3) -> (DVec3, DVec3) {
    let helper = if u.x.abs() < 0.6 {
        DVec3::X
    } else if u.y.abs() < 0.6 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let w1 = u.cross(helper).normalize();
    let w2 = u.cross(w1);
    (w1, w2)
}

struct Builder {
    out: Sites,
    band: Option<f64>,
    eta: f64,
}

impl Builder {
    /// Adds `n . p <= n . q + slack + eta` for unit `n`.
    fn plane(&mut self, n: DVec3, q: DVec3, slack: f64) {
        self.out.planes.push(HalfSpace {
            n,
            c: n.dot(q) + slack + self.eta,
        });
    }

    fn push(
        &mut self,
        kind: SiteKind,
        anchor: DVec3,
        rows: [DVec3; 3],
        first: usize,
        witness: DVec3,
        bounds: (DVec3, DVec3),
    ) {
        self.out.sites.push(Site {
            kind,
            anchor,
            rows,
            planes: (first as u32, self.out.planes.len() as u32),
            witness,
            bounds,
        });
    }

    fn face(&mut self, a: DVec3, b: DVec3, c: DVec3, n: DVec3) {
        let first = self.out.planes.len();
        for (p, q, r) in [(a, b, c), (b, c, a), (c, a, b)] {
            // Inward in-plane normal of edge pq: the prism is m . (x - p) >= 0.
            let mut m = n.cross(q - p).normalize();
            if m.dot(r - p) < 0.0 {
                m = -m;
            }
            self.plane(-m, p, 0.0);
        }
        if let Some(band) = self.band {
            self.plane(n, a, band);
            self.plane(-n, a, band);
        }
        self.push(
            SiteKind::Face,
            a,
            [n, b, c],
            first,
            (a + b + c) / 3.0,
            (a.min(b).min(c), a.max(b).max(c)),
        );
        self.out.counts.faces += 1;
    }

    /// Segment `[a, b]`; `thirds` are the third vertices of its non-degenerate incident
    /// faces (empty for an edge mesh or loose domains).
    fn edge(&mut self, a: DVec3, b: DVec3, thirds: &[DVec3]) {
        let ab = b - a;
        let len2 = ab.length_squared();
        if !(len2 > 0.0) {
            return;
        }
        let len = len2.sqrt();
        let u = ab / len;
        let first = self.out.planes.len();
        self.plane(-u, a, 0.0);
        self.plane(u, b, 0.0);
        for &w in thirds {
            let q = w - a;
            let t = q - q.dot(u) * u;
            let tl = t.length();
            if tl > 0.0 && tl.is_finite() {
                self.plane(t / tl, a, 0.0);
            }
        }
        let (w1, w2) = orthonormal_pair(u);
        self.push(
            SiteKind::Edge,
            a,
            [w1, w2, DVec3::ZERO],
            first,
            0.5 * (a + b),
            (a.min(b), a.max(b)),
        );
        self.out.counts.edges += 1;
    }

    /// Vertex `v` with unit cone directions `dirs` (neighbours).
    fn vertex(&mut self, v: DVec3, dirs: &[DVec3]) {
        let first = self.out.planes.len();
        for &d in dirs {
            self.plane(d, v, 0.0);
        }
        self.push(
            SiteKind::Vertex,
            v,
            [DVec3::X, DVec3::Y, DVec3::Z],
            first,
            v,
            (v, v),
        );
        self.out.counts.vertices += 1;
    }

    /// Vertex sites for every `used` vertex, with the polar cones of their `edges` when
    /// `tight`.
    fn vertices_of(&mut self, pos: &[DVec3], edges: &[[u32; 2]], used: &[bool], tight: bool) {
        let n = pos.len();
        let mut deg = vec![0u32; n + 1];
        for &[a, b] in edges {
            deg[a as usize] += 1;
            deg[b as usize] += 1;
        }
        let mut start = vec![0u32; n + 1];
        for i in 0..n {
            start[i + 1] = start[i] + deg[i];
        }
        let mut fill = start.clone();
        let mut nb = vec![0u32; start[n] as usize];
        for &[a, b] in edges {
            nb[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            nb[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        let mut dirs = Vec::new();
        for v in 0..n {
            if !used[v] {
                continue;
            }
            dirs.clear();
            if tight {
                for &w in &nb[start[v] as usize..start[v + 1] as usize] {
                    let d = pos[w as usize] - pos[v];
                    let l = d.length();
                    if l > 0.0 && l.is_finite() {
                        dirs.push(d / l);
                    }
                }
            }
            self.vertex(pos[v], &dirs);
        }
    }
}
