//! Structural checks of a built BVH, used by tests after every build.

use super::Bvh;
use crate::mesh::Aabb;

/// Checks that every primitive is in exactly one leaf, every node's box contains its
/// children's boxes and its primitives' boxes, and subtree sizes add up.
pub fn validate(bvh: &Bvh, bounds: &[Aabb]) -> Result<(), String> {
    let n = bounds.len();
    if bvh.order.len() != n {
        return Err(format!(
            "order has {} entries for {n} primitives",
            bvh.order.len()
        ));
    }
    let mut seen = vec![false; n];
    for &o in &bvh.order {
        let o = o as usize;
        if o >= n || seen[o] {
            return Err(format!("order is not a permutation (entry {o})"));
        }
        seen[o] = true;
    }
    if n == 0 {
        return Ok(());
    }
    let mut covered = 0usize;
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        let node = bvh.nodes.get(i).ok_or(format!("node {i} out of range"))?;
        let contains = |b: &Aabb| node.min.cmple(b.min).all() && node.max.cmpge(b.max).all();
        if node.is_leaf() {
            let (f, c) = (node.index as usize, node.count as usize);
            if f + c > n || c as u32 != node.size {
                return Err(format!("leaf {i} range {f}+{c} bad"));
            }
            for k in f..f + c {
                if !contains(&bounds[bvh.order[k] as usize]) {
                    return Err(format!("leaf {i} does not contain primitive {k}"));
                }
            }
            covered += c;
        } else {
            let (l, r) = (i + 1, node.index as usize);
            let (ln, rn) = (
                bvh.nodes.get(l).ok_or("left child missing")?,
                bvh.nodes.get(r).ok_or("right child missing")?,
            );
            if ln.size + rn.size != node.size {
                return Err(format!("node {i} size {} != children sum", node.size));
            }
            for ch in [ln, rn] {
                if !contains(&Aabb {
                    min: ch.min,
                    max: ch.max,
                }) {
                    return Err(format!("node {i} does not contain its child"));
                }
            }
            stack.push(l);
            stack.push(r);
        }
    }
    if covered != n {
        return Err(format!("leaves cover {covered} of {n} primitives"));
    }
    Ok(())
}
