//! Closing the parts of a closed mesh: the cross-sections of each cut plane
//! as cap faces (with holes).

use glam::DVec3;

use super::*;

impl<'m, 'b> Cutter<'m, 'b> {
    /// Sorts the routed items by part (stably) into `part_items`.
    pub(super) fn group_items_by_part(&mut self) {
        let b = &mut self.bufs;
        let nparts = b.planes.len() + 1;
        b.part_start.clear();
        b.part_start.resize(nparts + 1, 0);
        for &(p, _) in &b.items {
            b.part_start[p as usize + 1] += 1;
        }
        for p in 0..nparts {
            b.part_start[p + 1] += b.part_start[p];
        }
        b.part_items.clear();
        b.part_items.resize(b.items.len(), Item::Whole(0));
        // `remap` serves as the fill pointers here.
        let fill = &mut b.build.remap;
        fill.clear();
        fill.extend_from_slice(&b.part_start[..nparts]);
        for &(p, item) in &b.items {
            let f = &mut fill[p as usize];
            b.part_items[*f as usize] = item;
            *f += 1;
        }
    }

    pub(super) fn part_items(&self, part: usize) -> &[Item] {
        let b = &self.bufs;
        &b.part_items[b.part_start[part] as usize..b.part_start[part + 1] as usize]
    }

    /// True if every welded edge of the input is used as often in one
    /// direction as in the other (so cut parts can be closed with caps).
    pub(super) fn input_is_closed(&mut self) -> bool {
        let mesh = self.mesh;
        if mesh.faces.len() == 1 && self.face_has_distinct_vertices(0) {
            // One face whose corners are all different vertices uses every
            // edge once, in one direction (a facade being split: most
            // calls).
            return false;
        }
        let mut balance = std::mem::take(&mut self.bufs.build.balance);
        balance.clear();
        let mut any = false;
        for face in 0..mesh.faces.len() {
            if mesh.outer_loop(face).len < 3 {
                continue;
            }
            any = true;
            for &l in mesh.face_loops(face) {
                let r = mesh.loop_corners(l);
                for c in r.clone() {
                    let n = if c + 1 == r.end { r.start } else { c + 1 };
                    let (a, b) = (
                        self.original_vertex(c as u32),
                        self.original_vertex(n as u32),
                    );
                    if a != b {
                        let d = if a < b { 1 } else { -1 };
                        balance.push((edge_key(a, b), d));
                    }
                }
            }
        }
        balance.sort_unstable_by_key(|e| e.0);
        let balanced = balance
            .chunk_by(|x, y| x.0 == y.0)
            .all(|g| g.iter().map(|e| e.1).sum::<i32>() == 0);
        self.bufs.build.balance = balance;
        any && balanced
    }

    /// Whether the corners of `face` (all its loops) are distinct welded
    /// vertices; `false` for faces of more than 16 corners (not checked).
    fn face_has_distinct_vertices(&self, face: usize) -> bool {
        const MAX: usize = 16;
        let mesh = self.mesh;
        let mut seen = [0u32; MAX];
        let mut n = 0;
        for &l in mesh.face_loops(face) {
            for c in mesh.loop_corners(l) {
                let v = self.original_vertex(c as u32);
                if n == MAX || seen[..n].contains(&v) {
                    return false;
                }
                seen[n] = v;
                n += 1;
            }
        }
        true
    }

    /// Cap faces of `part` in plane `k`, facing `outward` (`+n` for the
    /// plane above the part, `-n` below), left in `caps`: each cap is an
    /// outer loop (then holes) of vertex ids, with the face whose material
    /// it takes.
    pub(super) fn caps(&self, part: usize, k: usize, outward: DVec3, cb: &mut CapBufs) {
        let tol = self.tol;
        cb.caps.clear();
        cb.loops.clear();
        cb.loop_verts.clear();
        cb.owner.clear();
        // Net count of directed on-plane edges per undirected edge, in the
        // order the edges are first seen.
        cb.seen.clear();
        let add = |a: u32, b: u32, face: u32, seen: &mut Vec<(u64, u32, i32, u32)>| {
            if a == b || !self.on_plane(a, k) || !self.on_plane(b, k) {
                return;
            }
            let rank = seen.len() as u32;
            seen.push((edge_key(a, b), rank, if a < b { 1 } else { -1 }, face));
        };
        let mesh = self.mesh;
        for item in self.part_items(part) {
            match *item {
                Item::Whole(face) => {
                    if mesh.outer_loop(face as usize).len < 3 {
                        continue;
                    }
                    for &l in mesh.face_loops(face as usize) {
                        let r = mesh.loop_corners(l);
                        for c in r.clone() {
                            let n = if c + 1 == r.end { r.start } else { c + 1 };
                            let (a, b) = (
                                self.original_vertex(c as u32),
                                self.original_vertex(n as u32),
                            );
                            add(a, b, face, &mut cb.seen);
                        }
                    }
                }
                Item::Piece(p) => {
                    let rec = self.bufs.pieces_rec[p as usize];
                    let (_, outer_len) = self.bufs.store_loops[rec.first as usize];
                    if outer_len < 3 {
                        continue;
                    }
                    for li in rec.first..rec.first + rec.count {
                        let (s, n) = self.bufs.store_loops[li as usize];
                        let cs = &self.bufs.store_corners[s as usize..(s + n) as usize];
                        for i in 0..cs.len() {
                            let j = if i + 1 == cs.len() { 0 } else { i + 1 };
                            add(cs[i].v, cs[j].v, rec.face, &mut cb.seen);
                        }
                    }
                }
            }
        }
        if cb.seen.is_empty() {
            return;
        }
        cb.seen.sort_unstable_by_key(|e| (e.0, e.1));
        cb.net.clear();
        for g in cb.seen.chunk_by(|x, y| x.0 == y.0) {
            let count: i32 = g.iter().map(|e| e.2).sum();
            cb.net.push((g[0].1, g[0].0, count, g[0].3));
        }
        cb.net.sort_unstable_by_key(|e| e.0);
        // Unmatched edges, reversed: the caps' boundary edges.
        cb.edges.clear();
        for &(_, key, count, face) in &cb.net {
            let (a, b) = ((key >> 32) as u32, key as u32);
            for _ in 0..count.unsigned_abs() {
                if count > 0 {
                    cb.edges.push((b, a, face));
                } else {
                    cb.edges.push((a, b, face));
                }
            }
        }
        if cb.edges.is_empty() {
            return;
        }
        let basis = plane_basis(outward);
        let p2 = |i: u32| self.to2d(i, basis);
        let edges = &cb.edges;
        // Out-edges per start vertex (in edge order for equal starts).
        cb.by_start.clear();
        cb.by_start.extend(0..edges.len() as u32);
        cb.by_start
            .sort_unstable_by_key(|&e| (edges[e as usize].0, e));
        let by_start = &cb.by_start;
        let first_out = |vtx: u32| by_start.partition_point(|&e| edges[e as usize].0 < vtx);
        cb.used.clear();
        cb.used.resize(edges.len(), false);
        for e0 in 0..edges.len() {
            if cb.used[e0] {
                continue;
            }
            cb.used[e0] = true;
            let start = cb.loop_verts.len();
            cb.loop_verts.push(edges[e0].0);
            let mut cur = e0;
            let mut closed = false;
            for _ in 0..=edges.len() {
                let (a, w, _) = edges[cur];
                let first = first_out(w);
                let usable = |e: usize| !cb.used[e] || e == e0;
                let mut outs = by_start[first..]
                    .iter()
                    .take_while(|&&e| edges[e as usize].0 == w)
                    .map(|&e| e as usize)
                    .filter(|&e| usable(e));
                let Some(only) = outs.next() else {
                    break; // open chain: the section is not closed here
                };
                // At a vertex where several continue, the sharpest turn
                // (largest angle from the way back) keeps loops simple.
                let e = if outs.next().is_none() {
                    only
                } else {
                    let back = p2(a) - p2(w);
                    let mut best: Option<(usize, f64)> = None;
                    for &e in by_start[first..]
                        .iter()
                        .take_while(|&&e| edges[e as usize].0 == w)
                    {
                        let e = e as usize;
                        if !usable(e) {
                            continue;
                        }
                        let dir = p2(edges[e].1) - p2(w);
                        let mut ang = back.perp_dot(dir).atan2(back.dot(dir));
                        if ang <= 0.0 {
                            ang += std::f64::consts::TAU;
                        }
                        if best.is_none_or(|(_, b)| ang > b) {
                            best = Some((e, ang));
                        }
                    }
                    best.map_or(only, |b| b.0)
                };
                if e == e0 {
                    closed = true;
                    break;
                }
                cb.used[e] = true;
                cb.loop_verts.push(edges[e].0);
                cur = e;
            }
            let len = cb.loop_verts.len() - start;
            if !closed || len < 3 {
                cb.loop_verts.truncate(start);
                continue;
            }
            let vs = &cb.loop_verts[start..];
            let area = signed_area_by(len, |i| p2(vs[i]));
            if area.abs() <= tol * tol {
                cb.loop_verts.truncate(start);
                continue;
            }
            cb.loops.push((start as u32, len as u32, edges[e0].2, area));
        }
        // Outer loops (counter-clockwise) become caps; each hole goes to the
        // smallest outer loop containing it.
        cb.owner.resize(cb.loops.len(), NONE);
        for (li, &(_, _, face, area)) in cb.loops.iter().enumerate() {
            if area > 0.0 {
                cb.owner[li] = cb.caps.len() as u32;
                cb.caps.push((li as u32, face, area));
            }
        }
        let loop_of = |li: usize| {
            let (s, n, _, _) = cb.loops[li];
            &cb.loop_verts[s as usize..(s + n) as usize]
        };
        for li in 0..cb.loops.len() {
            let area = cb.loops[li].3;
            if area > 0.0 {
                continue;
            }
            let verts = loop_of(li);
            let probe = hole_probe(verts, &p2, cb.caps.iter().map(|c| loop_of(c.0 as usize)));
            let mut best: Option<usize> = None;
            for (ci, &(outer, _, cap_area)) in cb.caps.iter().enumerate() {
                if cap_area > -area && best.is_none_or(|b| cap_area < cb.caps[b].2) {
                    let o = loop_of(outer as usize);
                    if point_in_polygon_by(probe, o.len(), |i| p2(o[i])) {
                        best = Some(ci);
                    }
                }
            }
            if let Some(b) = best {
                cb.owner[li] = b as u32;
            }
        }
    }

    /// Builds the output meshes.
    /// Where a piece of `face` starts its outer loop `cs`: at the edge that
    /// runs most nearly like the source face's first edge (ties: the earliest
    /// in the loop). A facade split into tiles and floors so keeps its first
    /// edges along the ground, and the pieces' `comp(f)` scopes keep the
    /// facade's orientation, whichever corner the cut reached first.
    pub(super) fn first_corner(
        &self,
        cs: &[WCorner],
        face: u32,
        reference: &mut Option<(u32, Option<DVec3>)>,
    ) -> usize {
        // The reference edge of the face, kept while its pieces come one
        // after the other.
        let reference = match *reference {
            Some((f, r)) if f == face => r,
            _ => {
                let r = self.reference_edge(face);
                *reference = Some((face, r));
                r
            }
        };
        let Some(reference) = reference else {
            return 0;
        };
        let verts = &self.bufs.verts;
        let mut best = (f64::NEG_INFINITY, 0);
        for i in 0..cs.len() {
            let next = if i + 1 == cs.len() { 0 } else { i + 1 };
            let e = verts[cs[next].v as usize] - verts[cs[i].v as usize];
            let len = e.length();
            if len <= self.tol {
                continue;
            }
            let along = e.dot(reference) / len;
            if along > best.0 + 1e-9 {
                best = (along, i);
            }
        }
        best.1
    }

    /// The direction of the first edge of `face`'s outer loop longer than
    /// the tolerance.
    fn reference_edge(&self, face: u32) -> Option<DVec3> {
        let mesh = self.mesh;
        let outer = mesh.loop_indices(mesh.outer_loop(face as usize));
        (0..outer.len())
            .map(|i| {
                mesh.positions[outer[(i + 1) % outer.len()] as usize]
                    - mesh.positions[outer[i] as usize]
            })
            .find(|e| e.length() > self.tol)
            .map(|e| e.normalize())
    }
}
