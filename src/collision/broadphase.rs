//! Sweep and prune over the geoms' world boxes (MuJoCo's broad phase, `mj_broadphase`
//! in engine_collision_driver.c, sweeps boxes along the principal axis of the geoms' positions):
//! which candidate pairs ([`Model::collision_pairs`]) can touch at the current poses, found in
//! time that grows with the geoms and the overlapping boxes instead of with all candidate pairs.
//!
//! Each geom with a finite bounding sphere gets the cube around it (centre ± (rbound + e)), with
//! e = (the largest margin + gap of any pair + `reach`) / 2: two geoms whose bounding spheres come
//! within their pair's margin + gap + reach have overlapping cubes along every axis, so the sweep
//! never loses a pair the exact bounding-sphere test that follows ([`super::collide`]) would keep.
//! The cubes are sorted along the world axis of largest spread and swept; each overlapping pair
//! of geoms is looked up among the candidate pairs (a dense geom-by-geom table for up to 512
//! geoms, else a sorted key table; built once). Pairs with a
//! plane or a height field (unbounded) are always passed on. The result is the candidate pairs'
//! indices in ascending order — `collision_pairs`' order — so contacts come out in the same order
//! as from the all-pairs loop, and the simulation is the same to the last bit.
//!
//! Models with few candidate pairs skip the sweep (`Broadphase::sweep` is false): testing every
//! pair's bounding spheres is then cheaper.

use crate::model::Model;
use crate::spatial::Transform;

/// Below this many candidate pairs between bounded geoms, every pair is tested directly.
const SWEEP_FROM_PAIRS: usize = 1000;
/// Up to this many geoms in the sweep, overlapping geoms find their pair in a dense table
/// (at most 1 MiB); above it, by binary search among the keys.
const DENSE_TABLE_GEOMS: usize = 512;
/// A table entry without a candidate pair.
const NO_PAIR: u32 = u32::MAX;

/// The model-constant part of the sweep: which geoms take part and how pairs are looked up.
#[derive(Clone, Debug, Default)]
pub struct Broadphase {
    /// Whether the sweep runs (enough candidate pairs between bounded geoms).
    pub sweep: bool,
    /// The geoms of the bounded pairs (finite bounding sphere), ascending.
    geoms: Vec<u32>,
    /// Per geom, its bounding radius (m).
    rbound: Vec<f64>,
    /// Half the largest margin + gap of any candidate pair (m).
    half_margin: f64,
    /// (lower geom << 32 | higher geom, pair index), sorted by key: the bounded pairs.
    keys: Vec<(u64, u32)>,
    /// The pairs with an unbounded geom (plane, height field), ascending.
    unbounded: Vec<u32>,
    /// With few geoms: each geom's position in `geoms` (`NO_PAIR` for the others) and the pair
    /// index of every two of them (`table[a · geoms.len() + b]`, `NO_PAIR` where they are no
    /// candidate pair); empty otherwise.
    local: Vec<u32>,
    table: Vec<u32>,
}

/// Per-step scratch of the sweep, in [`Data`](crate::Data): room for every participating geom and pair,
/// reserved once.
#[derive(Clone, Debug, Default)]
pub struct BroadphaseWork {
    /// (lower end along the sweep axis, geom) sorted by lower end.
    ends: Vec<(f64, u32)>,
    /// The candidate pairs that passed, ascending.
    pub(crate) pairs: Vec<u32>,
    /// Per candidate pair, the last collision pass (`pass`) that found it touching (0: none); a
    /// pair touching at the pass before this one skips the GJK test that proves most pairs
    /// apart (it would not), straight to its narrow phase. The contacts do not depend on it.
    pub(crate) touched: Vec<u64>,
    /// Per candidate pair, what its separation test keeps from the last pass (the hill-climb
    /// starts of its two hulls, the direction that proved it apart; see `ccd::separated`).
    pub(crate) warm: Vec<super::ccd::SeparationWarm>,
    /// The collision pass's number (counts the passes from 2): stamps the world boxes below and
    /// the touching pairs.
    pub(crate) pass: u64,
    /// Per geom with a bounding box (`CollisionModel::local_box`), that box at the geom's world
    /// pose for the oriented-bounding-box test, formed at the first pair of the pass that
    /// needs it: valid when `box_pass` holds this pass's number.
    pub(crate) boxes: Vec<super::obb::WorldBox>,
    /// Likewise the box along the geom frame's axes of a mesh that has one
    /// (`CollisionModel::file_box`), valid when `file_pass` holds this pass's number.
    pub(crate) file_boxes: Vec<super::obb::WorldBox>,
    /// The pass at which each geom's `boxes` entry was formed.
    pub(crate) box_pass: Vec<u64>,
    /// The pass at which each geom's `file_boxes` entry was formed.
    pub(crate) file_pass: Vec<u64>,
}

impl BroadphaseWork {
    /// Scratch sized for `model`'s sweep.
    pub fn new(model: &Model) -> Self {
        Self {
            ends: Vec::with_capacity(model.geoms.len()),
            pairs: Vec::with_capacity(model.collision_pairs.len()),
            touched: vec![0; model.collision_pairs.len()],
            warm: vec![super::ccd::SeparationWarm::none(); model.collision_pairs.len()],
            pass: 1,
            boxes: vec![super::obb::WorldBox::default(); model.geoms.len()],
            file_boxes: vec![super::obb::WorldBox::default(); model.geoms.len()],
            box_pass: vec![0; model.geoms.len()],
            file_pass: vec![0; model.geoms.len()],
        }
    }
}

impl BroadphaseWork {
    /// Forms geom `g`'s world box (its `local` box at world pose `x`) unless this pass has.
    #[inline]
    pub(crate) fn form_box(&mut self, g: usize, local: &super::obb::LocalBox, x: &Transform) {
        if self.box_pass[g] != self.pass {
            self.box_pass[g] = self.pass;
            self.boxes[g] = super::obb::WorldBox::new(local, x);
        }
    }

    /// Geom `g`'s box along its geom frame's axes (`file` at world pose `x`), formed unless
    /// this pass has.
    #[inline]
    pub(crate) fn form_file_box(
        &mut self,
        g: usize,
        file: &super::obb::LocalBox,
        x: &Transform,
    ) -> super::obb::WorldBox {
        if self.file_pass[g] != self.pass {
            self.file_pass[g] = self.pass;
            self.file_boxes[g] = super::obb::WorldBox::new(file, x);
        }
        self.file_boxes[g]
    }
}

fn key(a: usize, b: usize) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

impl Broadphase {
    /// The sweep's tables for `model`, with the geoms' bounding radii `rbound` (infinite for
    /// planes and height fields).
    pub fn new(model: &Model, rbound: &[f64]) -> Self {
        let mut keys = Vec::new();
        let mut unbounded = Vec::new();
        let mut in_sweep = vec![false; model.geoms.len()];
        let mut margin: f64 = 0.0;
        for (i, p) in model.collision_pairs.iter().enumerate() {
            let [g1, g2] = p.geom;
            margin = margin.max(p.margin + p.gap);
            if rbound[g1].is_finite() && rbound[g2].is_finite() {
                keys.push((key(g1, g2), i as u32));
                in_sweep[g1] = true;
                in_sweep[g2] = true;
            } else {
                unbounded.push(i as u32);
            }
        }
        keys.sort_unstable();
        let geoms: Vec<u32> = (0..model.geoms.len()).filter(|&g| in_sweep[g]).map(|g| g as u32).collect();
        let sweep = keys.len() >= SWEEP_FROM_PAIRS;
        let (mut local, mut table) = (Vec::new(), Vec::new());
        if sweep && geoms.len() <= DENSE_TABLE_GEOMS {
            let n = geoms.len();
            local = vec![NO_PAIR; model.geoms.len()];
            for (l, &g) in geoms.iter().enumerate() {
                local[g as usize] = l as u32;
            }
            table = vec![NO_PAIR; n * n];
            for &(k, i) in &keys {
                let (a, b) = (local[(k >> 32) as usize] as usize, local[(k & 0xffff_ffff) as usize] as usize);
                table[a * n + b] = i;
                table[b * n + a] = i;
            }
        }
        Self {
            sweep,
            geoms,
            rbound: rbound.to_vec(),
            half_margin: 0.5 * margin,
            keys,
            unbounded,
            local,
            table,
        }
    }

    /// The candidate pairs whose bounding spheres may come within margin + gap + `reach` at the
    /// geoms' world poses `x` (`Data::x_world_geom`, current), ascending, into `work.pairs`.
    pub fn candidates(&self, x: &[Transform], work: &mut BroadphaseWork, reach: f64) {
        work.pairs.clear();
        let e = self.half_margin + 0.5 * reach;
        // The axis of largest spread of the geom centres.
        let n = self.geoms.len() as f64;
        let (mut mean, mut sq) = ([0.0; 3], [0.0; 3]);
        for &g in &self.geoms {
            let p = x[g as usize].pos;
            for k in 0..3 {
                mean[k] += p[k];
                sq[k] += p[k] * p[k];
            }
        }
        let spread = |k: usize| sq[k] - mean[k] * mean[k] / n.max(1.0);
        let axis = (0..3).max_by(|&a, &b| spread(a).total_cmp(&spread(b))).unwrap_or(0);
        work.ends.clear();
        for &g in &self.geoms {
            let r = self.rbound[g as usize] + e;
            work.ends.push((x[g as usize].pos[axis] - r, g));
        }
        work.ends.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        for i in 0..work.ends.len() {
            let (lo_i, gi) = work.ends[i];
            let (pi, ri) = (x[gi as usize].pos, self.rbound[gi as usize] + e);
            let hi_i = lo_i + 2.0 * ri;
            for &(lo_j, gj) in &work.ends[i + 1..] {
                if lo_j > hi_i {
                    break;
                }
                let (pj, rj) = (x[gj as usize].pos, self.rbound[gj as usize] + e);
                let apart = (0..3).any(|k| k != axis && (pi[k] - pj[k]).abs() > ri + rj);
                if apart {
                    continue;
                }
                if self.table.is_empty() {
                    if let Ok(at) =
                        self.keys.binary_search_by_key(&key(gi as usize, gj as usize), |&(k, _)| k)
                    {
                        work.pairs.push(self.keys[at].1);
                    }
                } else {
                    let n = self.geoms.len();
                    let pair =
                        self.table[self.local[gi as usize] as usize * n + self.local[gj as usize] as usize];
                    if pair != NO_PAIR {
                        work.pairs.push(pair);
                    }
                }
            }
        }
        work.pairs.extend_from_slice(&self.unbounded);
        work.pairs.sort_unstable();
    }
}
