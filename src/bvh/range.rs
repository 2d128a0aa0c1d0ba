//! What the two ways of splitting a range share: the build's input (the primitives'
//! boxes, or none for points) and the bounds of a range of records, of the primitives
//! and of their centroids. The binned split ([`super::build`]) and the sweep of small
//! ranges ([`super::sweep`]) both read them; neither owns the other's types.
//!
//! A range's primitive bounds give the node's box; its centroid bounds give the axis and
//! the extent the binning divides (SAH, Wald 2007).

use super::bins::Item;
use crate::mesh::Aabb;
use glam::Vec3;

/// The primitives being built over.
pub(super) struct Input<'a> {
    /// Primitive boxes by input index; `None` when every box is its centroid (points),
    /// then binning reads the centroids only.
    pub bounds: Option<&'a [Aabb]>,
    pub leaf_size: usize,
}

impl Input<'_> {
    #[inline]
    pub fn bounds_of(&self, item: &Item) -> Aabb {
        match self.bounds {
            Some(b) => b[item.index as usize],
            None => {
                let c = Vec3::from_array(item.c);
                Aabb { min: c, max: c }
            }
        }
    }
}

/// Bounds of a range: of its primitives and of their centroids.
#[derive(Clone, Copy)]
pub(super) struct RangeBounds {
    pub prims: Aabb,
    pub centroids: Aabb,
}

impl RangeBounds {
    pub const EMPTY: RangeBounds = RangeBounds {
        prims: Aabb::EMPTY,
        centroids: Aabb::EMPTY,
    };

    /// Grown by one primitive.
    pub fn grow(self, input: &Input, it: &Item) -> RangeBounds {
        RangeBounds {
            prims: self.prims.union(input.bounds_of(it)),
            centroids: self.centroids.grow(it.centroid()),
        }
    }

    pub fn union(self, o: RangeBounds) -> RangeBounds {
        RangeBounds {
            prims: self.prims.union(o.prims),
            centroids: self.centroids.union(o.centroids),
        }
    }
}

/// Bounds of the primitives and of the centroids of `items`.
pub(super) fn range_bounds(input: &Input, items: &[Item]) -> RangeBounds {
    items
        .iter()
        .fold(RangeBounds::EMPTY, |acc, it| acc.grow(input, it))
}
