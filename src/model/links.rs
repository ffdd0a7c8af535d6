//! MuJoCo's bodies over lagrange's compiled bodies (docs/architecture.md, "Layers").
//!
//! lagrange compiles a file's bodies into a tree of *compiled* bodies, one per movable joint:
//! bodies welded to their parent are fused into it and an MJCF body with several joints becomes a
//! chain. Every file body (URDF link, MJCF body, the MJCF world first) survives as a frame of kind
//! [`FrameKind::Link`](super::FrameKind::Link), and those frames, in order, are MuJoCo's bodies:
//! MuJoCo's body id `b` is the `b`-th link frame. Quantities MuJoCo defines per body — `xfrc_applied`,
//! `subtree_com`, `cfrc_int`, the bodies sensors name — are indexed by these ids, and this table
//! maps them to frames and to each other.

/// MuJoCo's body table: id `b` ↔ link frame, parent, and which body every frame and geom is on.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Links {
    /// The frame of each MuJoCo body (index in `Model::frames`, a frame of kind `Link`).
    pub frame: Vec<usize>,
    /// MuJoCo's `body_parentid`: the parent body of each body (the world's parent is itself, 0).
    pub parent: Vec<usize>,
    /// For each frame of `Model::frames`: the MuJoCo body it is on (MuJoCo's `site_bodyid` for
    /// sites; the owning body for the joint-anchor frames of a multi-joint body).
    pub of_frame: Vec<usize>,
    /// For each geom of `Model::geoms`: MuJoCo's `geom_bodyid`.
    pub of_geom: Vec<usize>,
    /// The orientation of each body's inertial (principal) frame in the body frame, `[w, x, y, z]`
    /// (MuJoCo's `body_iquat`: an `<inertial>`'s own `quat` with `diaginertia`, else the principal
    /// axes MuJoCo's compiler finds, moments in decreasing order).
    pub iquat: Vec<[f64; 4]>,
    /// For each geom of `Model::geoms`: MuJoCo's `geom_sameframe`, the frame of its body it takes
    /// its pose from (placed by `io::sameframe`); `None` for a mesh that does not collide (its
    /// MuJoCo frame is not computed: it keeps its own pose).
    pub geom_sameframe: Vec<SameFrame>,
    /// For each frame of `Model::frames`: MuJoCo's `site_sameframe` for sites, `None` for others.
    pub site_sameframe: Vec<SameFrame>,
}

impl Links {
    /// The number of MuJoCo bodies (the world included for MJCF models).
    pub fn len(&self) -> usize {
        self.frame.len()
    }

    /// Whether the table is empty (a model compiled without links).
    pub fn is_empty(&self) -> bool {
        self.frame.is_empty()
    }

    /// Builds the table from the spec links' kinds and parents (`kind_is_link[l]`, `parent[l]`,
    /// in the spec's depth-first order) and the spec link each frame and geom was made from.
    pub(crate) fn build(
        kind_is_link: &[bool],
        spec_parent: &[Option<usize>],
        frame_spec_link: &[usize],
        geom_spec_link: &[usize],
    ) -> Links {
        let n = kind_is_link.len();
        // The body id of each spec link: its own rank for a body; for a joint link of a
        // multi-joint body, the rank of the body link that closes its chain.
        let mut id = vec![0usize; n];
        let mut parent = Vec::new();
        let mut rank = 0;
        for l in 0..n {
            if kind_is_link[l] {
                id[l] = rank;
                // Nearest ancestor that is a body link.
                let mut p = spec_parent[l];
                while let Some(pl) = p {
                    if kind_is_link[pl] {
                        break;
                    }
                    p = spec_parent[pl];
                }
                parent.push(p.map_or(rank, |pl| id[pl]));
                rank += 1;
            }
        }
        for l in (0..n).rev() {
            if !kind_is_link[l] {
                id[l] = (l..n).find(|&k| kind_is_link[k]).map_or(0, |k| id[k]);
            }
        }
        // The world (or a root) is its own parent: MuJoCo's body 0 has parent 0.
        if let Some(first) = parent.first_mut() {
            *first = 0;
        }
        let frame = frame_spec_link
            .iter()
            .enumerate()
            .filter(|&(_, &l)| kind_is_link[l])
            .scan(usize::MAX, |last, (f, &l)| {
                // The first frame made from a body link is the link's own frame.
                let own = *last != l;
                *last = l;
                Some(own.then_some(f))
            })
            .flatten()
            .collect();
        Links {
            frame,
            parent,
            of_frame: frame_spec_link.iter().map(|&l| id[l]).collect(),
            of_geom: geom_spec_link.iter().map(|&l| id[l]).collect(),
            iquat: Vec::new(),
            geom_sameframe: Vec::new(),
            site_sameframe: Vec::new(),
        }
    }
}

/// Which frame of its body a geom or site shares (MuJoCo's `mjtSameFrame`, same numbering).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SameFrame {
    /// Its own pose in the body (`mjSAMEFRAME_NONE`, 0).
    #[default]
    None = 0,
    /// The body's frame (`mjSAMEFRAME_BODY`, 1).
    Body = 1,
    /// The body frame's rotation at its own position (`mjSAMEFRAME_BODYROT`, 3).
    BodyRot = 3,
    /// The body's inertial frame (`mjSAMEFRAME_INERTIA`, 2).
    Inertia = 2,
    /// The inertial frame's rotation at its own position (`mjSAMEFRAME_INERTIAROT`, 4).
    InertiaRot = 4,
}

impl SameFrame {
    /// MuJoCo's number for the flag (`geom_sameframe`, `site_sameframe`).
    pub fn mujoco_code(self) -> u8 {
        self as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_links_belong_to_the_body_that_closes_their_chain() {
        // world, body a (two joints: joint link j, then a), body b child of a.
        let kind = [true, false, true, true];
        let parent = [None, Some(0), Some(1), Some(2)];
        // Frames: world, j, a, a's site, b.
        let frames = [0, 1, 2, 2, 3];
        let geoms = [0, 2, 3];
        let t = Links::build(&kind, &parent, &frames, &geoms);
        assert_eq!(t.frame, vec![0, 2, 4]);
        assert_eq!(t.parent, vec![0, 0, 1]);
        assert_eq!(t.of_frame, vec![0, 1, 1, 1, 2]);
        assert_eq!(t.of_geom, vec![0, 1, 2]);
    }
}
