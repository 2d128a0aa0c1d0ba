//! The order the image loop traces its tiles in: the heaviest first, from one queue.
//!
//! Tiles are traced independently (`render::image`), so their order changes no pixel and
//! no count; it only decides how long the threads wait for each other at the end. On a
//! view where the object covers a few tiles, those tiles hold nearly all the work (every
//! hit ray and the near misses around it), and when one of them is the last to start,
//! the other threads sit idle for most of a tile: on the published full bunny at 480x270
//! (24 of 510 tiles hold 99% of its leaves) two threads took 0.265 s for 0.476 s of
//! one-thread work in image order, 0.234 s in this one (doc/performance-log.md, round
//! twenty-five).
//!
//! Longest processing time first (Graham's list scheduling: each thread takes the next
//! tile of a shared queue, the heaviest first) leaves at most the last tile's time idle,
//! and the last tiles are the light ones. A tile's weight is estimated before any ray is
//! traced from where the surfaces can be: the boxes of each primitive set's BVH nodes
//! with about `1 / BOXES_PER_SET` of its primitives each are projected onto the image
//! (the rectangle around their corners' projections, `Camera::project`), and a tile
//! weighs the number of boxes whose rectangle overlaps it. A box with a corner behind
//! the camera (or on its plane) counts on every tile: it can project anywhere. Ties keep
//! the image order. The estimate only orders the work; a wrong one costs time, never a
//! different image.

use super::cone::Tile;
use super::object::TraceObject;
use crate::camera::Camera;
use crate::primitives::AnySet;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// About how many boxes per primitive set estimate where its surface projects.
pub const BOXES_PER_SET: usize = 512;

/// The indices of `tiles` (cells of a grid of `side`-pixel squares, [`tile_weights`]),
/// heaviest first by the projected boxes of `objects` seen through `camera` (module
/// docs); ties in the order of `tiles`.
pub fn heaviest_first(
    objects: &[TraceObject],
    camera: &Camera,
    tiles: &[Tile],
    side: u32,
) -> Vec<usize> {
    let weights = tile_weights(objects, camera, tiles, side);
    let mut order: Vec<usize> = (0..tiles.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(weights[i]));
    order
}

/// How many projected boxes overlap each of `tiles` (their pixel rectangles, edges
/// included), a box with a corner behind the camera counting on every tile. The tiles
/// are cells of one grid of `side x side` pixels from the image's corner (the last row
/// and column may be narrower), as the image loop makes them.
pub fn tile_weights(
    objects: &[TraceObject],
    camera: &Camera,
    tiles: &[Tile],
    side: u32,
) -> Vec<u32> {
    let mut weights = vec![0u32; tiles.len()];
    if tiles.is_empty() {
        return weights;
    }
    // The tiles' grid cells, and where each tile sits among them.
    let cell = |t: &Tile| ((t.x0 / side) as usize, (t.y0 / side) as usize);
    let (cx0, cy0) = tiles
        .iter()
        .map(cell)
        .fold((usize::MAX, usize::MAX), |a, c| {
            (a.0.min(c.0), a.1.min(c.1))
        });
    let (cx1, cy1) = tiles
        .iter()
        .map(cell)
        .fold((0, 0), |a, c| (a.0.max(c.0), a.1.max(c.1)));
    let columns = cx1 - cx0 + 1;
    let mut at = vec![usize::MAX; columns * (cy1 - cy0 + 1)];
    for (i, t) in tiles.iter().enumerate() {
        let (cx, cy) = cell(t);
        at[(cy - cy0) * columns + cx - cx0] = i;
    }
    // The cells a pixel interval `[a, b]` touches, within `lo..=hi`: a tile's interval
    // `[k side, k side + w]` includes its far edge.
    let span = |a: f64, b: f64, lo: usize, hi: usize| {
        let side = f64::from(side);
        let first = ((a / side).ceil() - 1.0).max(lo as f64);
        let last = (b / side).floor().min(hi as f64);
        (first as usize, last as usize)
    };
    let mut everywhere = 0u32;
    for rect in objects
        .iter()
        .flat_map(|o| o.sets.iter())
        .flat_map(set_boxes)
        .map(|(lo, hi)| projected_rect(camera, lo, hi))
    {
        let Some([x0, y0, x1, y1]) = rect else {
            everywhere += 1;
            continue;
        };
        let (first_x, last_x) = span(x0, x1, cx0, cx1);
        let (first_y, last_y) = span(y0, y1, cy0, cy1);
        if x1 < 0.0 || y1 < 0.0 || first_x > last_x || first_y > last_y {
            continue;
        }
        for cy in first_y..=last_y {
            for cx in first_x..=last_x {
                let i = at[(cy - cy0) * columns + cx - cx0];
                // A tile's own width decides at the image's narrower last column and row.
                if let Some(t) = tiles.get(i)
                    && f64::from(t.x0) <= x1
                    && f64::from(t.x0 + t.w) >= x0
                    && f64::from(t.y0) <= y1
                    && f64::from(t.y0 + t.h) >= y0
                {
                    weights[i] += 1;
                }
            }
        }
    }
    for w in &mut weights {
        *w += everywhere;
    }
    weights
}

/// The boxes of the BVH nodes of `set` that hold at most `len / BOXES_PER_SET`
/// primitives (rounded up) and whose parent holds more, and of the leaves above that
/// size: the tree's cut at about [`BOXES_PER_SET`] boxes.
fn set_boxes(set: &AnySet) -> Vec<(DVec3, DVec3)> {
    let nodes = &set.bvh().nodes;
    let most = set.len().div_ceil(BOXES_PER_SET).max(1) as u32;
    let mut boxes = Vec::new();
    let mut stack = if nodes.is_empty() { vec![] } else { vec![0] };
    while let Some(i) = stack.pop() {
        let n = &nodes[i];
        if n.is_leaf() || n.size <= most {
            boxes.push((n.min.as_dvec3(), n.max.as_dvec3()));
        } else {
            stack.extend([i + 1, n.index as usize]);
        }
    }
    boxes
}

/// The pixel rectangle `[x0, y0, x1, y1]` around the projections of the box's corners,
/// or `None` when a corner is not in front of the camera (or so close to its plane that
/// its projection is not finite).
fn projected_rect(camera: &Camera, lo: DVec3, hi: DVec3) -> Option<[f64; 4]> {
    let mut r = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for k in 0..8 {
        let corner = DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        let (x, y) = camera
            .project(corner)
            .filter(|p| p.0.is_finite() && p.1.is_finite())?;
        r = [r[0].min(x), r[1].min(y), r[2].max(x), r[3].max(y)];
    }
    Some(r)
}

/// Runs `work(i)` for every index of `order` on the current thread pool, each thread
/// taking the next index of the queue in `order`'s order, and returns the results by
/// index (`results[i] = work(i)`), or `None` as soon as any `work` returns `None` (a
/// cancelled render). `order` must be a permutation of `0..order.len()`.
pub fn run_in_order<T: Send>(
    order: &[usize],
    work: impl Fn(usize) -> Option<T> + Sync,
) -> Option<Vec<T>> {
    let next = AtomicUsize::new(0);
    let workers = rayon::current_num_threads().max(1);
    let done: Vec<Vec<(usize, Option<T>)>> = (0..workers)
        .into_par_iter()
        .map(|_| {
            let mut done = Vec::new();
            while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
                let r = work(i);
                let stop = r.is_none();
                done.push((i, r));
                if stop {
                    // Let the other threads stop at their next tile.
                    next.store(order.len(), Ordering::Relaxed);
                    break;
                }
            }
            done
        })
        .collect();
    let mut results: Vec<Option<T>> = (0..order.len()).map(|_| None).collect();
    for (i, r) in done.into_iter().flatten() {
        results[i] = Some(r?);
    }
    results.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::EvalParams;
    use crate::primitives::PrimitiveKind;
    use crate::procedural;

    fn tiles(w: u32, h: u32, side: u32) -> Vec<Tile> {
        (0..h.div_ceil(side))
            .flat_map(|ty| {
                (0..w.div_ceil(side)).map(move |tx| Tile {
                    x0: tx * side,
                    y0: ty * side,
                    w: side.min(w - tx * side),
                    h: side.min(h - ty * side),
                })
            })
            .collect()
    }

    #[test]
    fn results_come_back_by_index_whatever_the_order() {
        let order = [3, 0, 4, 1, 2];
        let r = run_in_order(&order, |i| Some(10 * i)).unwrap();
        assert_eq!(r, vec![0, 10, 20, 30, 40]);
        assert_eq!(run_in_order(&order, |i| (i != 4).then_some(i)), None);
        assert_eq!(run_in_order::<u8>(&[], |_| None), Some(vec![]));
    }

    #[test]
    fn tiles_where_a_small_object_projects_come_first() {
        // A torus of radius 0.15 at the world origin, seen from 5 units away: it covers
        // the middle of a 160x96 image and no tile near its corners.
        let mesh = procedural::torus(0.1, 0.05, 24, 12);
        let set = AnySet::build(&mesh, PrimitiveKind::Triangles).unwrap();
        let object = TraceObject::new(vec![set], EvalParams::new(100.0, 1.0, 0.5));
        let camera = Camera::new(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::ZERO,
            DVec3::Y,
            53.13,
            160,
            96,
        )
        .unwrap();
        let tiles = tiles(160, 96, 16);
        let weights = tile_weights(std::slice::from_ref(&object), &camera, &tiles, 16);
        let order = heaviest_first(std::slice::from_ref(&object), &camera, &tiles, 16);
        let (cx, cy) = camera.project(DVec3::ZERO).unwrap();
        let centre = tiles
            .iter()
            .position(|t| {
                (f64::from(t.x0)..f64::from(t.x0 + t.w)).contains(&cx)
                    && (f64::from(t.y0)..f64::from(t.y0 + t.h)).contains(&cy)
            })
            .unwrap();
        assert!(weights[centre] > 0, "{weights:?}");
        assert_eq!(weights[0], 0, "the top-left tile sees no box: {weights:?}");
        let first_empty = order.iter().position(|&i| weights[i] == 0).unwrap();
        assert!(order[..first_empty].contains(&centre));
        assert!(order[..first_empty].iter().all(|&i| weights[i] > 0));
        // Ties keep the image order.
        let empties = &order[first_empty..];
        assert!(empties.windows(2).all(|w| w[0] < w[1]));
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..tiles.len()).collect::<Vec<_>>());
    }

    #[test]
    fn the_grid_counts_what_testing_every_box_against_every_tile_counts() {
        let mesh = procedural::torus(0.5, 0.2, 32, 16);
        let set = AnySet::build(&mesh, PrimitiveKind::Edges).unwrap();
        let object = TraceObject::new(vec![set], EvalParams::new(30.0, 30.0, 0.5));
        let boxes = set_boxes(&object.sets[0]);
        for (origin, (w, h)) in [
            (DVec3::new(0.3, 0.8, 2.5), (200, 120)),
            (DVec3::new(-1.5, 0.2, 0.4), (97, 61)),
            (DVec3::new(0.0, 0.1, 0.6), (64, 48)),
        ] {
            let camera = Camera::new(origin, DVec3::ZERO, DVec3::Y, 53.13, w, h).unwrap();
            let all = tiles(w, h, 16);
            // A crop's tiles: the grid's cells from (1, 1) on.
            let crop: Vec<Tile> = all
                .iter()
                .copied()
                .filter(|t| t.x0 >= 16 && t.y0 >= 16)
                .collect();
            for tiles in [all, crop] {
                let got = tile_weights(std::slice::from_ref(&object), &camera, &tiles, 16);
                let want: Vec<u32> = tiles
                    .iter()
                    .map(|t| {
                        let (x0, y0) = (f64::from(t.x0), f64::from(t.y0));
                        let (x1, y1) = (x0 + f64::from(t.w), y0 + f64::from(t.h));
                        boxes
                            .iter()
                            .filter(|&&(lo, hi)| match projected_rect(&camera, lo, hi) {
                                None => true,
                                Some([a, b, c, d]) => a <= x1 && c >= x0 && b <= y1 && d >= y0,
                            })
                            .count() as u32
                    })
                    .collect();
                assert_eq!(got, want, "camera at {origin}");
                assert!(got.iter().any(|&w| w > 0));
            }
        }
    }

    #[test]
    fn a_box_around_the_camera_weighs_on_every_tile() {
        let mesh = procedural::sphere_points(1.0, 2000);
        let set = AnySet::build(&mesh, PrimitiveKind::Points).unwrap();
        let object = TraceObject::new(vec![set], EvalParams::new(10.0, 1.0, 0.5));
        let camera = Camera::new(DVec3::ZERO, DVec3::Z, DVec3::Y, 60.0, 64, 64).unwrap();
        let tiles = tiles(64, 64, 16);
        let weights = tile_weights(std::slice::from_ref(&object), &camera, &tiles, 16);
        assert!(weights.iter().all(|&w| w >= 1), "{weights:?}");
    }
}
