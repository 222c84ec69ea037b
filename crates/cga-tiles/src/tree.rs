//! The spatial tree of a tileset: a quadtree over the lots' centres in the
//! ground plane (x east, z south), split until a tile holds few lots.

/// A tile of the tree: its lots (leaves only) or its children.
pub struct Node {
    /// Level (the root is 0) and position in the level's grid: the tile's
    /// name.
    pub level: u32,
    pub x: u32,
    pub y: u32,
    /// The lots of a leaf, by index, in lot order.
    pub lots: Vec<usize>,
    pub children: Vec<Node>,
}

impl Node {
    /// Every lot under this tile, in the order of the leaves.
    pub fn all_lots(&self) -> Vec<usize> {
        let mut out = Vec::new();
        self.collect(&mut out);
        out
    }

    /// The leaves under this tile (itself, if it is one), in the order of
    /// a walk of the tree: children in order, depth first.
    pub fn leaves(&self) -> Vec<&Node> {
        let mut out = Vec::new();
        self.collect_leaves(&mut out);
        out
    }

    fn collect_leaves<'a>(&'a self, out: &mut Vec<&'a Node>) {
        if self.children.is_empty() {
            out.push(self);
        }
        for c in &self.children {
            c.collect_leaves(out);
        }
    }

    fn collect(&self, out: &mut Vec<usize>) {
        out.extend(&self.lots);
        for c in &self.children {
            c.collect(out);
        }
    }

    /// The tile's name: `LEVEL_X_Y`.
    pub fn name(&self) -> String {
        format!("{}_{}_{}", self.level, self.x, self.y)
    }
}

/// Orders `lots` along a Z curve (Morton order) over their centres
/// (`centre` of a lot: x, z), so that consecutive lots lie close together.
pub fn z_order(lots: &mut [usize], centre: impl Fn(usize) -> [f64; 2]) {
    let points: Vec<[f64; 2]> = lots.iter().map(|&i| centre(i)).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
    // 16 bits per axis, interleaved.
    let code = |p: [f64; 2]| -> u32 {
        let q = |k: usize| (((p[k] - lo[k]) / size * 65535.0).clamp(0.0, 65535.0)) as u32;
        let spread = |mut v: u32| {
            v = (v | (v << 8)) & 0x00ff_00ff;
            v = (v | (v << 4)) & 0x0f0f_0f0f;
            v = (v | (v << 2)) & 0x3333_3333;
            (v | (v << 1)) & 0x5555_5555
        };
        spread(q(0)) | (spread(q(1)) << 1)
    };
    let mut keyed: Vec<(u32, usize)> = points
        .into_iter()
        .map(code)
        .zip(lots.iter().copied())
        .collect();
    keyed.sort();
    for (slot, (_, i)) in lots.iter_mut().zip(keyed) {
        *slot = i;
    }
}

/// Deeper than this, lots that share a centre stay in one tile.
const MAX_LEVEL: u32 = 20;

/// The quadtree over `centres` (x, z) with at most `max_lots` lots per
/// leaf (more only where lots share a point).
pub fn build(centres: &[[f64; 2]], max_lots: usize) -> Node {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for c in centres {
        for k in 0..2 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    if centres.is_empty() {
        (lo, hi) = ([0.0; 2], [1.0; 2]);
    }
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
    let all: Vec<usize> = (0..centres.len()).collect();
    split(centres, all, lo, size, 0, 0, 0, max_lots.max(1))
}

#[allow(clippy::too_many_arguments)]
fn split(
    centres: &[[f64; 2]],
    lots: Vec<usize>,
    origin: [f64; 2],
    size: f64,
    level: u32,
    x: u32,
    y: u32,
    max_lots: usize,
) -> Node {
    if lots.len() <= max_lots || level >= MAX_LEVEL {
        return Node {
            level,
            x,
            y,
            lots,
            children: Vec::new(),
        };
    }
    let half = size / 2.0;
    let mut quads: [Vec<usize>; 4] = Default::default();
    for i in lots {
        let c = centres[i];
        let qx = usize::from(c[0] >= origin[0] + half);
        let qy = usize::from(c[1] >= origin[1] + half);
        quads[qy * 2 + qx].push(i);
    }
    let children = quads
        .into_iter()
        .enumerate()
        .filter(|(_, q)| !q.is_empty())
        .map(|(q, lots)| {
            let (qx, qy) = ((q % 2) as u32, (q / 2) as u32);
            let o = [origin[0] + half * qx as f64, origin[1] + half * qy as f64];
            split(
                centres,
                lots,
                o,
                half,
                level + 1,
                x * 2 + qx,
                y * 2 + qy,
                max_lots,
            )
        })
        .collect();
    Node {
        level,
        x,
        y,
        lots: Vec::new(),
        children,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_hold_at_most_the_limit_and_every_lot_once() {
        let centres: Vec<[f64; 2]> = (0..1000)
            .map(|i| [(i % 40) as f64 * 10.0, (i / 40) as f64 * 7.0])
            .collect();
        let root = build(&centres, 16);
        let mut all = root.all_lots();
        assert_eq!(all.len(), 1000);
        all.sort();
        assert!(all.iter().enumerate().all(|(k, &i)| k == i));
        fn check(n: &Node) {
            if n.children.is_empty() {
                assert!(n.lots.len() <= 16, "{} lots", n.lots.len());
            } else {
                assert!(n.lots.is_empty());
                n.children.iter().for_each(check);
            }
        }
        check(&root);
    }

    #[test]
    fn lots_on_one_point_stop_at_the_deepest_level() {
        let root = build(&[[5.0, 5.0]; 10], 2);
        fn depth(n: &Node) -> u32 {
            n.children.iter().map(depth).max().unwrap_or(n.level)
        }
        assert!(depth(&root) <= MAX_LEVEL);
        assert_eq!(root.all_lots().len(), 10);
    }
}
