//! Splitting one face (with its holes) along a plane into pieces: the
//! direct path for simple convex faces and the general one.

use glam::{DVec2, DVec3};

use super::*;

impl<'m, 'b> Cutter<'m, 'b> {
    /// The corner where plane `k` crosses the edge from corner `ci` to `cj`
    /// (strictly on opposite sides), shared by every face using that edge.
    pub(super) fn crossing_corner(&mut self, ci: WCorner, cj: WCorner, k: usize) -> WCorner {
        // The original edge the sub-edge ci→cj lies on.
        let on_original_edge = ci.a != CAP && (cj.a == ci.a || (cj.a == ci.b && cj.t == 0.0));
        let (va, vb) = if on_original_edge {
            (self.original_vertex(ci.a), self.original_vertex(ci.b))
        } else {
            (ci.v, cj.v)
        };
        let (sa, sb) = (self.dist(va, k), self.dist(vb, k));
        let t_face = sa / (sa - sb);
        let key = edge_key(va, vb);
        let v = match self.bufs.crossings.find(key, k as u32) {
            Ok(v) => v,
            Err(slot) => {
                // Compute from the lower id to the higher so that the point
                // does not depend on which face asks first.
                let (p, q, sp, sq) = if va < vb {
                    (va, vb, sa, sb)
                } else {
                    (vb, va, sb, sa)
                };
                let t = sp / (sp - sq);
                let (pp, pq) = (self.bufs.verts[p as usize], self.bufs.verts[q as usize]);
                let mut x = pp + (pq - pp) * t;
                if let Some(a) = self.axis {
                    x[a] = self.bufs.planes[k];
                }
                self.bufs.verts.push(x);
                let v = self.bufs.verts.len() as u32 - 1;
                self.bufs.crossings.insert_at(slot, key, k as u32, v);
                v
            }
        };
        if on_original_edge {
            WCorner {
                v,
                a: ci.a,
                b: ci.b,
                t: t_face,
            }
        } else {
            // Not on an original edge (cannot happen with parallel planes):
            // take the attributes of the nearer end.
            let src = if t_face < 0.5 { ci } else { cj };
            WCorner { v, ..src }
        }
    }

    /// Splits an edge shape (a loop of two corners) at plane `k`.
    pub(super) fn split_segment(&mut self, k: usize) -> Split {
        let (c0, c1) = (self.bufs.cur.corners[0], self.bufs.cur.corners[1]);
        let x = self.crossing_corner(c0, c1, k);
        let (lower, upper) = if self.dist(c0.v, k) < 0.0 {
            ([c0, x], [x, c1])
        } else {
            ([x, c1], [c0, x])
        };
        let p = &mut self.bufs.pieces;
        p.clear();
        for (side, l) in [(0, lower), (1, upper)] {
            let start = p.corners.len();
            p.corners.extend_from_slice(&l);
            let l = p.add_loop(start, side);
            p.add_piece(l);
        }
        Split::Pieces
    }

    /// Splits the polygon in `cur`, with vertices strictly on both sides of
    /// plane `k`, into pieces below and above (see the module docs), left in
    /// `pieces`.
    /// The common case of a split, done directly: a polygon without holes
    /// and without repeated vertices, no vertex of which lies on plane `k`,
    /// crossing it at exactly two edges (every convex face that is cut).
    /// The piece below is stored, the piece above left in `cur`. The result
    /// is exactly what [`Cutter::split_polygon`] gives (the same crossing
    /// vertices created in the same order, the same corners in the same
    /// order, the same pieces dropped for a negative area); it returns
    /// `NotApplicable` for anything else, having at most created crossing
    /// vertices the general path finds again.
    pub(super) fn split_simple(&mut self, face: u32, normal: DVec3, k: usize) -> Simple {
        const MAX: usize = 16;
        if !fast_paths_enabled() {
            return Simple::NotApplicable;
        }
        let tol = self.tol;
        let cur = &self.bufs.cur;
        let n = cur.corners.len();
        if cur.loops.len() != 1 || !(3..=MAX).contains(&n) {
            return Simple::NotApplicable;
        }
        let mut above = [false; MAX];
        let mut dist = [0.0; MAX];
        for (i, c) in cur.corners.iter().enumerate() {
            let s = self.dist(c.v, k);
            // On the plane (or NaN): the general path decides.
            if s.abs() <= tol || s.is_nan() {
                return Simple::NotApplicable;
            }
            above[i] = s > tol;
            dist[i] = s;
        }
        let mut edges = [0usize; 2];
        let mut m = 0;
        for e in 0..n {
            if above[e] != above[if e + 1 == n { 0 } else { e + 1 }] {
                if m == 2 {
                    return Simple::NotApplicable;
                }
                edges[m] = e;
                m += 1;
            }
        }
        if m != 2 {
            return Simple::NotApplicable;
        }
        for i in 1..n {
            let v = cur.corners[i].v;
            if cur.corners[..i].iter().any(|c| c.v == v) {
                return Simple::NotApplicable;
            }
        }
        // The crossings, created in edge order as the general path does,
        // with their position and tie-break along the cut line.
        let d = normal.cross(self.n);
        let mut xs = [(
            WCorner {
                v: 0,
                a: 0,
                b: 0,
                t: 0.0,
            },
            0.0,
            0.0,
            false,
        ); 2];
        for (x, &e) in xs.iter_mut().zip(&edges) {
            let j = if e + 1 == n { 0 } else { e + 1 };
            let (ci, cj) = (self.bufs.cur.corners[e], self.bufs.cur.corners[j]);
            let corner = self.crossing_corner(ci, cj, k);
            let (lo, hi, slo, shi) = if above[e] {
                (cj, ci, dist[j], dist[e])
            } else {
                (ci, cj, dist[e], dist[j])
            };
            let verts = &self.bufs.verts;
            let dl = verts[hi.v as usize] - verts[lo.v as usize];
            *x = (
                corner,
                verts[corner.v as usize].dot(d),
                dl.dot(d) / (shi - slo),
                above[j],
            );
        }
        if xs[0].0.v == xs[1].0.v {
            return Simple::NotApplicable;
        }
        // The general path pairs the crossings in order along the line (a
        // stable sort): the first must go up, the second down.
        let second_first = xs[1]
            .1
            .total_cmp(&xs[0].1)
            .then(xs[1].2.total_cmp(&xs[0].2))
            .is_lt();
        let (first, second) = if second_first {
            (xs[1], xs[0])
        } else {
            (xs[0], xs[1])
        };
        if !first.3 || second.3 {
            return Simple::NotApplicable;
        }
        // Below: from the crossing going down along the loop to the one
        // going up; above: the rest.
        let (xd, ed, xu, eu) = if xs[0].3 {
            (xs[1].0, edges[1], xs[0].0, edges[0])
        } else {
            (xs[0].0, edges[0], xs[1].0, edges[1])
        };
        // Pieces with a negative area are dropped, as the general path
        // does (they would be holes with no piece around them).
        let basis = self.basis;
        let mut p2 = [DVec2::ZERO; MAX];
        for (q, c) in p2.iter_mut().zip(&self.bufs.cur.corners) {
            *q = self.to2d(c.v, basis);
        }
        let (pd, pu) = (self.to2d(xd.v, basis), self.to2d(xu.v, basis));
        let area = |x0: DVec2, e0: usize, x1: DVec2, e1: usize| {
            let mut seq = [DVec2::ZERO; MAX + 2];
            seq[0] = x0;
            let mut len = 1;
            let mut e = e0;
            loop {
                e = if e + 1 == n { 0 } else { e + 1 };
                seq[len] = p2[e];
                len += 1;
                if e == e1 {
                    break;
                }
            }
            seq[len] = x1;
            signed_area_by(len + 1, |i| seq[i])
        };
        let mut piece = std::mem::take(&mut self.bufs.split.cleaned);
        if area(pd, ed, pu, eu) >= 0.0 {
            trace_piece(&self.bufs.cur.corners, &mut piece, (xd, ed), (xu, eu));
            let b = &mut self.bufs;
            b.store_loops
                .push((b.store_corners.len() as u32, piece.len() as u32));
            b.store_corners.extend_from_slice(&piece);
            b.pieces_rec.push(PieceRec {
                face,
                first: b.store_loops.len() as u32 - 1,
                count: 1,
            });
            b.items
                .push((k as u32, Item::Piece(b.pieces_rec.len() as u32 - 1)));
        }
        let keep = area(pu, eu, pd, ed) >= 0.0;
        if keep {
            trace_piece(&self.bufs.cur.corners, &mut piece, (xu, eu), (xd, ed));
            let cur = &mut self.bufs.cur;
            std::mem::swap(&mut cur.corners, &mut piece);
            cur.loops[0] = (0, cur.corners.len() as u32);
        }
        self.bufs.split.cleaned = piece;
        count_simple_split();
        Simple::Done { above: keep }
    }

    pub(super) fn split_polygon(&mut self, normal: DVec3, k: usize) -> Split {
        let poly = std::mem::take(&mut self.bufs.cur);
        let mut sc = std::mem::take(&mut self.bufs.split);
        let split = self.split_polygon_with(&poly, normal, k, &mut sc);
        self.bufs.split = sc;
        if let Split::Whole(_) = split {
            // Inconsistent input (self-intersecting or badly non-planar
            // polygon): keep the face whole on the side of its centroid
            // rather than produce garbage.
            let c = poly.corners.iter().map(|c| self.dist(c.v, k)).sum::<f64>()
                / poly.corners.len() as f64;
            self.bufs.cur = poly;
            return Split::Whole(c > 0.0 || c.is_nan());
        }
        self.bufs.cur = poly;
        split
    }

    pub(super) fn split_polygon_with(
        &mut self,
        poly: &Poly,
        normal: DVec3,
        k: usize,
        sc: &mut SplitBufs,
    ) -> Split {
        let tol = self.tol;
        sc.xs.clear();
        sc.at_edge.clear();
        sc.at_edge.resize(poly.corners.len(), NONE);
        // Direction of the cut line along which the part below keeps itself
        // on the left: d = N × n.
        let d = normal.cross(self.n);
        for li in 0..poly.loops.len() {
            let (start, len) = poly.loops[li];
            for e in 0..len {
                let i = (start + e) as usize;
                let j = (start + (e + 1) % len) as usize;
                let (ci, cj) = (poly.corners[i], poly.corners[j]);
                let (si, sj) = (self.dist(ci.v, k), self.dist(cj.v, k));
                let (ai, aj) = (si > tol, sj > tol);
                if ai == aj {
                    continue;
                }
                let corner = if !ai && si >= -tol {
                    ci
                } else if !aj && sj >= -tol {
                    cj
                } else {
                    self.crossing_corner(ci, cj, k)
                };
                let (lo, hi) = if ai { (cj, ci) } else { (ci, cj) };
                let (slo, shi) = if ai { (sj, si) } else { (si, sj) };
                let verts = &self.bufs.verts;
                let dl = verts[hi.v as usize] - verts[lo.v as usize];
                sc.at_edge[i] = sc.xs.len() as u32;
                sc.xs.push(Crossing {
                    corner,
                    lp: li as u32,
                    edge: e,
                    lambda: verts[corner.v as usize].dot(d),
                    tie: dl.dot(d) / (shi - slo),
                    up: aj,
                });
            }
        }
        let m = sc.xs.len();
        sc.order.clear();
        sc.order.extend(0..m as u32);
        {
            let xs = &sc.xs;
            sc.order.sort_by(|&a, &b| {
                let (a, b) = (&xs[a as usize], &xs[b as usize]);
                a.lambda.total_cmp(&b.lambda).then(a.tie.total_cmp(&b.tie))
            });
        }
        sc.partner.clear();
        sc.partner.resize(m, NONE);
        let mut valid = m >= 2 && m.is_multiple_of(2);
        if valid {
            for p in sc.order.chunks_exact(2) {
                let (a, b) = (p[0] as usize, p[1] as usize);
                if !sc.xs[a].up || sc.xs[b].up {
                    valid = false;
                    break;
                }
                sc.partner[a] = b as u32;
                sc.partner[b] = a as u32;
            }
        }
        if !valid {
            return Split::Whole(false);
        }

        let basis = self.basis;
        // The face's vertices on the cut line, by position along it. A jump
        // along the line passes through those lying between its ends: this
        // keeps edges of the line shared between pieces and caps (no
        // T-junctions) and exposes where a piece touches the line from the
        // other side, where it is then split (see `split_pinches`).
        sc.online.clear();
        for c in &poly.corners {
            if self.on_plane(c.v, k) {
                sc.online.push((self.bufs.verts[c.v as usize].dot(d), *c));
            }
        }
        sc.online
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.v.cmp(&b.1.v)));
        sc.online.dedup_by_key(|x| x.1.v);
        let mut res = std::mem::take(&mut self.bufs.pieces);
        res.clear();
        for side in 0..2 {
            // side 0: below (entered at crossings going down), 1: above.
            let entering_up = side == 1;
            sc.visited.clear();
            sc.visited.resize(m, false);
            for s0 in 0..m {
                if sc.xs[s0].up != entering_up || sc.visited[s0] {
                    continue;
                }
                sc.traced.clear();
                let mut cur = s0;
                let mut guard = poly.corners.len() + 2 * m + 4;
                loop {
                    sc.visited[cur] = true;
                    let x = sc.xs[cur];
                    sc.traced.push(x.corner);
                    // Walk the loop to its next crossing.
                    let (start, len) = poly.loops[x.lp as usize];
                    let mut e = (x.edge + 1) % len;
                    let exit = loop {
                        sc.traced.push(poly.corners[(start + e) as usize]);
                        let c = sc.at_edge[(start + e) as usize];
                        if c != NONE {
                            break c as usize;
                        }
                        e = (e + 1) % len;
                    };
                    let ex = sc.xs[exit];
                    sc.traced.push(ex.corner);
                    cur = sc.partner[exit] as usize;
                    // Along the line to the partner, through on-line vertices.
                    let en = sc.xs[cur];
                    let (l0, l1) = (ex.lambda.min(en.lambda), ex.lambda.max(en.lambda));
                    let a = sc.online.partition_point(|o| o.0 <= l0);
                    let b = sc.online.partition_point(|o| o.0 < l1);
                    if a < b {
                        let skip = |c: &WCorner| c.v == ex.corner.v || c.v == en.corner.v;
                        if ex.lambda <= en.lambda {
                            for o in &sc.online[a..b] {
                                if !skip(&o.1) {
                                    sc.traced.push(o.1);
                                }
                            }
                        } else {
                            for o in sc.online[a..b].iter().rev() {
                                if !skip(&o.1) {
                                    sc.traced.push(o.1);
                                }
                            }
                        }
                    }
                    guard = guard.saturating_sub(1);
                    if cur == s0 || guard == 0 {
                        break;
                    }
                }
                if guard == 0 {
                    continue;
                }
                let first_new = res.loops.len();
                self.split_pinches(
                    &sc.traced,
                    k,
                    side,
                    &mut sc.slot,
                    &mut sc.cleaned,
                    &mut sc.pinch,
                    &mut res,
                );
                for l in first_new..res.loops.len() {
                    // Counter-clockwise loops are pieces, clockwise ones
                    // holes of the piece around them.
                    let c = res.corners_of(l);
                    if signed_area_by(c.len(), |i| self.to2d(c[i].v, basis)) >= 0.0 {
                        res.add_piece(l);
                    }
                }
            }
        }
        // Loops without crossings lie on one side: holes of the piece that
        // contains them (or, for a malformed face, pieces of their own).
        for li in 0..poly.loops.len() {
            let l = poly.loop_slice(li);
            let (start, len) = poly.loops[li];
            if (start..start + len).any(|i| sc.at_edge[i as usize] != NONE) {
                continue;
            }
            let side = usize::from(l.iter().any(|c| self.dist(c.v, k) > tol));
            let at = res.corners.len();
            if !self.clean_loop_into(l, k, &mut res.corners) {
                continue;
            }
            let nl = res.add_loop(at, side);
            if li == 0 {
                res.add_piece(nl);
            }
        }
        // Holes (clockwise traced loops first, then the loops without
        // crossings) go to the piece of their side containing them.
        for side in 0..2u8 {
            let count = res.pieces.iter().filter(|p| p.0 == side).count();
            for h in 0..res.loops.len() {
                let hl = res.loops[h];
                if hl.side != side || hl.owner != NONE {
                    continue;
                }
                if count == 0 {
                    continue; // a hole without a piece around it: nothing to cut out of
                }
                let cl = res.corners_of(h);
                let probe = cl
                    .iter()
                    .find(|c| self.dist(c.v, k).abs() > tol)
                    .map(|c| self.to2d(c.v, basis));
                let mut of_side = (0..res.pieces.len()).filter(|&p| res.pieces[p].0 == side);
                let first = of_side.clone().next().unwrap_or(0);
                let target = match probe {
                    Some(q) if count > 1 => of_side
                        .find(|&p| {
                            let o = res.corners_of(res.pieces[p].1 as usize);
                            point_in_polygon_by(q, o.len(), |i| self.to2d(o[i].v, basis))
                        })
                        .unwrap_or(first),
                    _ => first,
                };
                res.loops[h].owner = target as u32;
            }
        }
        self.bufs.pieces = res;
        Split::Pieces
    }

    /// Appends `l` to `out` without repeated consecutive vertices; returns
    /// false, leaving `out` as it was, if fewer than three remain or all lie
    /// on plane `k` (a piece without area).
    pub(super) fn clean_loop_into(&self, l: &[WCorner], k: usize, out: &mut Vec<WCorner>) -> bool {
        let base = out.len();
        for &c in l {
            if out.len() > base && out[out.len() - 1].v == c.v {
                continue;
            }
            out.push(c);
        }
        while out.len() - base > 1 && out[base].v == out[out.len() - 1].v {
            out.pop();
        }
        if out.len() - base < 3 || out[base..].iter().all(|c| self.on_plane(c.v, k)) {
            out.truncate(base);
            return false;
        }
        true
    }

    /// Splits a traced loop where it visits a vertex twice (a piece touching
    /// itself on the cut line, or a bridge along an edge lying in the line)
    /// into simple loops, dropping those without area; appends them to
    /// `out` on `side`, unowned.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn split_pinches(
        &self,
        l: &[WCorner],
        k: usize,
        side: usize,
        slot: &mut Vec<u32>,
        cleaned: &mut Vec<WCorner>,
        stack: &mut Vec<WCorner>,
        out: &mut Pieces,
    ) {
        cleaned.clear();
        if !self.clean_loop_into(l, k, cleaned) {
            return;
        }
        if slot.len() < self.bufs.verts.len() {
            slot.resize(self.bufs.verts.len(), NONE);
        }
        stack.clear();
        for &c in cleaned.iter() {
            let p = slot[c.v as usize];
            if p != NONE {
                // Close the sub-loop from the first visit up to here.
                let p = p as usize;
                for s in &stack[p + 1..] {
                    slot[s.v as usize] = NONE;
                }
                let at = out.corners.len();
                if self.clean_loop_into(&stack[p..], k, &mut out.corners) {
                    out.add_loop(at, side);
                }
                stack.truncate(p + 1);
                continue;
            }
            slot[c.v as usize] = stack.len() as u32;
            stack.push(c);
        }
        for s in stack.iter() {
            slot[s.v as usize] = NONE;
        }
        let at = out.corners.len();
        if self.clean_loop_into(stack, k, &mut out.corners) {
            out.add_loop(at, side);
        }
    }
}
