//! The point filters of a lidar object, applied while the records stream in: ASPRS
//! classes kept or dropped, returns, a crop box in file coordinates, and thinning (every
//! k-th point, or one point per voxel: the one nearest the voxel centre).
//!
//! Every test is made on the exact f64 file coordinates (scale and offset applied),
//! before recentring, so a crop box or a voxel grid written in file coordinates means
//! what it says.

use glam::DVec3;
use std::collections::HashMap;

/// The ASPRS noise classes (low point, high noise): dropped unless a scene says otherwise.
pub const NOISE_CLASSES: [u8; 2] = [7, 18];

/// Which returns of each pulse to keep.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Returns {
    #[default]
    All,
    /// Return number 1.
    First,
    /// Return number equal to the number of returns.
    Last,
}

impl Returns {
    pub const NAMES: &'static str = "\"first\", \"last\" or \"all\"";

    pub fn from_name(name: &str) -> Option<Returns> {
        match name {
            "all" => Some(Returns::All),
            "first" => Some(Returns::First),
            "last" => Some(Returns::Last),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Returns::All => "all",
            Returns::First => "first",
            Returns::Last => "last",
        }
    }

    fn keeps(self, return_number: u8, number_of_returns: u8) -> bool {
        match self {
            Returns::All => true,
            Returns::First => return_number == 1,
            Returns::Last => return_number == number_of_returns,
        }
    }
}

/// Thinning after the other filters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Thin {
    /// Keep the 1st, (k+1)-th, (2k+1)-th ... point that passed the other filters (k >= 1).
    Every(u64),
    /// One point per cube of this edge length (file units; the grid has a corner at the
    /// file's coordinate origin): the one nearest the cube's centre, the first in file
    /// order on a tie.
    Voxel(f64),
}

/// The filters of one lidar object. The default keeps every point except the noise
/// classes.
#[derive(Clone, Debug, PartialEq)]
pub struct LasFilters {
    /// Keep only these classes (`None`: all).
    pub classes: Option<Vec<u8>>,
    /// Drop these classes. Default [`NOISE_CLASSES`].
    pub exclude_classes: Vec<u8>,
    pub returns: Returns,
    /// Keep points inside this box (file coordinates, bounds included).
    pub crop: Option<[DVec3; 2]>,
    pub thin: Option<Thin>,
}

impl Default for LasFilters {
    fn default() -> Self {
        LasFilters {
            classes: None,
            exclude_classes: NOISE_CLASSES.to_vec(),
            returns: Returns::All,
            crop: None,
            thin: None,
        }
    }
}

/// How many points one filter let through.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FilterCount {
    /// The filter as a scene would write it (`classes = [2, 6]`), or `read` for the file.
    pub filter: String,
    pub kept: u64,
}

/// One record's fields that the filters look at.
#[derive(Clone, Copy, Debug)]
pub struct Record {
    pub p: DVec3,
    pub class: u8,
    pub return_number: u8,
    pub number_of_returns: u8,
}

/// The streaming part of the filters (everything but voxel thinning), with counts.
pub struct Stream<'a> {
    filters: &'a LasFilters,
    /// Points that passed each filter: read, classes, exclude, returns, crop, every.
    passed: [u64; 6],
}

impl<'a> Stream<'a> {
    pub fn new(filters: &'a LasFilters) -> Stream<'a> {
        Stream {
            filters,
            passed: [0; 6],
        }
    }

    /// Whether the record passes the classes, returns, crop and every-k filters.
    pub fn keeps(&mut self, r: &Record) -> bool {
        let f = self.filters;
        self.passed[0] += 1;
        if let Some(keep) = &f.classes
            && !keep.contains(&r.class)
        {
            return false;
        }
        self.passed[1] += 1;
        if f.exclude_classes.contains(&r.class) {
            return false;
        }
        self.passed[2] += 1;
        if !f.returns.keeps(r.return_number, r.number_of_returns) {
            return false;
        }
        self.passed[3] += 1;
        if let Some([min, max]) = f.crop
            && !(r.p.cmpge(min).all() && r.p.cmple(max).all())
        {
            return false;
        }
        self.passed[4] += 1;
        if let Some(Thin::Every(k)) = f.thin
            && !(self.passed[4] - 1).is_multiple_of(k)
        {
            return false;
        }
        self.passed[5] += 1;
        true
    }

    /// The count after each filter that is set, starting with the records read.
    /// `voxel_kept` is the count after voxel thinning, when there is one.
    pub fn counts(&self, voxel_kept: Option<u64>) -> Vec<FilterCount> {
        let f = self.filters;
        let list = |v: &[u8]| {
            let items: Vec<String> = v.iter().map(|c| c.to_string()).collect();
            format!("[{}]", items.join(", "))
        };
        let mut out = vec![FilterCount {
            filter: "read".to_string(),
            kept: self.passed[0],
        }];
        let mut push = |filter: String, kept: u64| out.push(FilterCount { filter, kept });
        if let Some(c) = &f.classes {
            push(format!("classes = {}", list(c)), self.passed[1]);
        }
        if !f.exclude_classes.is_empty() {
            push(
                format!("exclude_classes = {}", list(&f.exclude_classes)),
                self.passed[2],
            );
        }
        if f.returns != Returns::All {
            push(
                format!("returns = \"{}\"", f.returns.name()),
                self.passed[3],
            );
        }
        if let Some([min, max]) = f.crop {
            push(
                format!(
                    "crop = {{ min = [{}, {}, {}], max = [{}, {}, {}] }}",
                    min.x, min.y, min.z, max.x, max.y, max.z
                ),
                self.passed[4],
            );
        }
        match f.thin {
            Some(Thin::Every(k)) => push(format!("thin = {{ every = {k} }}"), self.passed[5]),
            Some(Thin::Voxel(v)) => push(
                format!("thin = {{ voxel = {v} }}"),
                voxel_kept.unwrap_or(self.passed[5]),
            ),
            None => {}
        }
        out
    }
}

/// One point per voxel, the nearest to the voxel's centre: fed the points that passed
/// the streaming filters, in order, with their index among them.
pub struct VoxelThin {
    size: f64,
    /// Voxel -> (index of the best point so far, its squared distance to the centre,
    /// its exact coordinates).
    best: HashMap<[i64; 3], (u32, f64, DVec3)>,
}

impl VoxelThin {
    pub fn new(size: f64) -> VoxelThin {
        VoxelThin {
            size,
            best: HashMap::new(),
        }
    }

    pub fn add(&mut self, index: u32, p: DVec3) {
        let cell = (p / self.size).floor();
        let key = [cell.x as i64, cell.y as i64, cell.z as i64];
        let centre = (cell + 0.5) * self.size;
        let d2 = (p - centre).length_squared();
        let e = self.best.entry(key).or_insert((index, d2, p));
        if d2 < e.1 {
            *e = (index, d2, p);
        }
    }

    /// Which of the `n` points to keep, and the exact bounds of those kept.
    pub fn finish(self, n: usize) -> (Vec<bool>, Option<[DVec3; 2]>) {
        let mut keep = vec![false; n];
        let mut bounds: Option<[DVec3; 2]> = None;
        for (index, _, p) in self.best.into_values() {
            keep[index as usize] = true;
            bounds = Some(match bounds {
                None => [p, p],
                Some([lo, hi]) => [lo.min(p), hi.max(p)],
            });
        }
        (keep, bounds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(x: f64, class: u8, rn: u8, nr: u8) -> Record {
        Record {
            p: DVec3::new(x, 0.0, 0.0),
            class,
            return_number: rn,
            number_of_returns: nr,
        }
    }

    #[test]
    fn stream_counts_each_filter() {
        let f = LasFilters {
            classes: Some(vec![2, 6, 7]),
            returns: Returns::Last,
            crop: Some([DVec3::splat(-1.0), DVec3::new(10.0, 1.0, 1.0)]),
            thin: Some(Thin::Every(2)),
            ..Default::default()
        };
        let recs = [
            rec(0.0, 2, 1, 1),  // kept (1st after crop)
            rec(1.0, 3, 1, 1),  // class
            rec(2.0, 7, 1, 1),  // noise
            rec(3.0, 6, 1, 2),  // not last
            rec(30.0, 6, 2, 2), // cropped
            rec(4.0, 6, 2, 2),  // 2nd after crop: thinned
            rec(5.0, 2, 3, 3),  // 3rd after crop: kept
        ];
        let mut s = Stream::new(&f);
        let kept: Vec<bool> = recs.iter().map(|r| s.keeps(r)).collect();
        assert_eq!(kept, [true, false, false, false, false, false, true]);
        let counts: Vec<u64> = s.counts(None).iter().map(|c| c.kept).collect();
        assert_eq!(counts, [7, 6, 5, 4, 3, 2]);
    }

    #[test]
    fn voxel_keeps_the_point_nearest_the_centre() {
        let mut v = VoxelThin::new(1.0);
        v.add(0, DVec3::new(0.1, 0.1, 0.1));
        v.add(1, DVec3::new(0.25, 0.5, 0.5));
        v.add(2, DVec3::new(0.75, 0.5, 0.5)); // tie with 1: the first stays
        v.add(3, DVec3::new(-0.5, 0.5, 0.5)); // another voxel
        let (keep, bounds) = v.finish(4);
        assert_eq!(keep, [false, true, false, true]);
        assert_eq!(
            bounds,
            Some([DVec3::new(-0.5, 0.5, 0.5), DVec3::new(0.25, 0.5, 0.5)])
        );
    }
}
