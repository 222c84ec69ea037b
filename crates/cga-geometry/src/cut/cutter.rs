//! The cutter: welding, routing each face through the planes, storing the
//! pieces by part.

use glam::{DVec2, DVec3};

use crate::mesh::Mesh;

use super::*;

pub(super) struct Cutter<'m, 'b> {
    pub(super) mesh: &'m Mesh,
    pub(super) n: DVec3,
    /// For axis-aligned cuts, the axis (crossing vertices get that coordinate
    /// set exactly to the plane's, so caps are exactly planar).
    pub(super) axis: Option<usize>,
    pub(super) tol: f64,
    /// The plane coordinates of the face being routed (see
    /// [`Cutter::face_basis`]).
    pub(super) basis: (DVec3, DVec3),
    /// The one part to build, open (without caps), or `None` for all of
    /// them, closed with caps where the mesh is closed (a trim keeps only
    /// the part above its plane, open: building the other is wasted).
    pub(super) only_part: Option<usize>,
    pub(super) bufs: &'b mut Bufs,
}

impl<'m, 'b> Cutter<'m, 'b> {
    pub(super) fn new(
        mesh: &'m Mesh,
        n: DVec3,
        offsets: &[f64],
        bufs: &'b mut Bufs,
    ) -> Cutter<'m, 'b> {
        // Sanitise the offsets: ascending, finite (NaN sorts as "no cut": it
        // is replaced by its predecessor, or -inf for the first).
        let planes = &mut bufs.planes;
        planes.clear();
        let mut prev = f64::NEG_INFINITY;
        for &o in offsets {
            let o = if o.is_nan() { prev } else { o.max(prev) };
            planes.push(o);
            prev = o;
        }
        let tol = mesh_tolerance(mesh).max(
            1e-9 * planes
                .iter()
                .filter(|p| p.is_finite())
                .fold(0.0f64, |m, p| m.max(p.abs())),
        );
        weld_points_into(&mesh.positions, tol, &mut bufs.vid, &mut bufs.rep);
        bufs.verts.clear();
        bufs.verts
            .extend(bufs.rep.iter().map(|&i| mesh.positions[i as usize]));
        bufs.crossings.clear();
        bufs.items.clear();
        bufs.store_corners.clear();
        bufs.store_loops.clear();
        bufs.pieces_rec.clear();
        let axis = [DVec3::X, DVec3::Y, DVec3::Z].iter().position(|&a| a == n);
        Cutter {
            mesh,
            n,
            axis,
            tol,
            basis: (DVec3::X, DVec3::Y),
            only_part: None,
            bufs,
        }
    }

    #[inline]
    pub(super) fn height(&self, v: u32) -> f64 {
        let p = self.bufs.verts[v as usize];
        match self.axis {
            Some(a) => p[a],
            None => self.n.dot(p),
        }
    }

    #[inline]
    pub(super) fn dist(&self, v: u32, k: usize) -> f64 {
        self.height(v) - self.bufs.planes[k]
    }

    #[inline]
    pub(super) fn on_plane(&self, v: u32, k: usize) -> bool {
        self.dist(v, k).abs() <= self.tol
    }

    #[inline]
    pub(super) fn original_vertex(&self, corner: u32) -> u32 {
        self.bufs.vid[self.mesh.corners[corner as usize] as usize]
    }

    /// A vertex in the coordinates `(u, v)` of a plane.
    #[inline]
    pub(super) fn to2d(&self, v: u32, (u, w): (DVec3, DVec3)) -> DVec2 {
        let p = self.bufs.verts[v as usize];
        DVec2::new(p.dot(u), p.dot(w))
    }

    pub(super) fn nplanes(&self) -> usize {
        self.bufs.planes.len()
    }

    pub(super) fn run(&mut self) {
        let mesh = self.mesh;
        for face in 0..mesh.faces.len() {
            // Height range of the whole face.
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            for &l in mesh.face_loops(face) {
                for c in mesh.loop_corners(l) {
                    let h = self.height(self.original_vertex(c as u32));
                    lo = lo.min(h);
                    hi = hi.max(h);
                }
            }
            if lo.partial_cmp(&hi).is_none_or(|o| o.is_gt()) {
                // No corners (or non-finite positions): keep it in part 0.
                self.bufs.items.push((0, Item::Whole(face as u32)));
                continue;
            }
            // Skip the planes the face lies strictly above.
            let tol = self.tol;
            let mut k = self.bufs.planes.partition_point(|&c| lo - c > tol);
            let degenerate = mesh.outer_loop(face).len < 3;
            loop {
                if k == self.nplanes() {
                    self.bufs.items.push((k as u32, Item::Whole(face as u32)));
                    break;
                }
                let c = self.bufs.planes[k];
                let has_neg = lo - c < -tol;
                let has_pos = hi - c > tol;
                match (has_neg, has_pos) {
                    (true, false) => {
                        self.bufs.items.push((k as u32, Item::Whole(face as u32)));
                        break;
                    }
                    (false, true) => k += 1,
                    (false, false) => {
                        // In the plane: below if the normal points up
                        // (it closes the part below), else above. Edge and
                        // vertex shapes have no normal and stay below.
                        let up = degenerate || face_normal(mesh, face).dot(self.n) > 0.0;
                        if up {
                            self.bufs.items.push((k as u32, Item::Whole(face as u32)));
                            break;
                        }
                        k += 1;
                    }
                    (true, true) => {
                        self.load_face(face);
                        let normal = face_normal(mesh, face);
                        self.route(face as u32, normal, k);
                        break;
                    }
                }
            }
        }
    }

    /// Loads the face into `cur` as a polygon of corners that remember their
    /// original edge.
    pub(super) fn load_face(&mut self, face: usize) {
        let mesh = self.mesh;
        let mut poly = std::mem::take(&mut self.bufs.cur);
        poly.clear();
        for &l in mesh.face_loops(face) {
            let start = poly.corners.len() as u32;
            let r = mesh.loop_corners(l);
            for c in r.clone() {
                let next = if c + 1 == r.end { r.start } else { c + 1 };
                poly.corners.push(WCorner {
                    v: self.original_vertex(c as u32),
                    a: c as u32,
                    b: next as u32,
                    t: 0.0,
                });
            }
            poly.loops.push((start, l.len));
        }
        self.bufs.cur = poly;
    }

    /// Routes the polygon in `cur` (a face crossing plane `k`) through the
    /// planes from `k` on: splits it, stores the pieces below each plane and
    /// routes the pieces above on, depth first (the order in which the
    /// pieces reach each part is that of a recursion over the pieces).
    pub(super) fn route(&mut self, face: u32, normal: DVec3, k: usize) {
        debug_assert!(self.bufs.stack.polys.is_empty());
        self.basis = self.face_basis(normal);
        self.route_one(face, normal, k);
        while let Some((first, count, k)) = self.bufs.stack.polys.pop() {
            let b = &mut self.bufs;
            b.cur.clear();
            let base = b.stack.loops[first as usize].0;
            for &(s, n) in &b.stack.loops[first as usize..(first + count) as usize] {
                b.cur.loops.push((s - base, n));
            }
            b.cur
                .corners
                .extend_from_slice(&b.stack.corners[base as usize..]);
            b.stack.loops.truncate(first as usize);
            b.stack.corners.truncate(base as usize);
            self.route_one(face, normal, k as usize);
        }
    }

    /// Routes `cur` from plane `k` on until it is stored or split; the
    /// pieces above a split are pushed on the stack.
    pub(super) fn route_one(&mut self, face: u32, normal: DVec3, mut k: usize) {
        loop {
            if k == self.nplanes() {
                self.store_cur(face, k);
                return;
            }
            match self.classify(k) {
                Side::Below => {
                    self.store_cur(face, k);
                    return;
                }
                Side::Above => k += 1,
                Side::On => {
                    if self.bufs.cur.corners.len() < 3 || normal.dot(self.n) > 0.0 {
                        self.store_cur(face, k);
                        return;
                    }
                    k += 1;
                }
                Side::Both => {
                    match self.split_simple(face, normal, k) {
                        Simple::NotApplicable => {}
                        Simple::Done { above: true } => {
                            k += 1;
                            continue;
                        }
                        Simple::Done { above: false } => return,
                    }
                    let split = if self.bufs.cur.loops[0].1 < 3 {
                        self.split_segment(k)
                    } else {
                        self.split_polygon(normal, k)
                    };
                    match split {
                        Split::Whole(false) => {
                            self.store_cur(face, k);
                            return;
                        }
                        Split::Whole(true) => k += 1,
                        Split::Pieces => {
                            let pieces = std::mem::take(&mut self.bufs.pieces);
                            for p in 0..pieces.pieces.len() {
                                if pieces.pieces[p].0 == 0 {
                                    self.store_piece(face, &pieces, p, k);
                                }
                            }
                            // Pushed in reverse, so that the first piece
                            // above is routed first.
                            for p in (0..pieces.pieces.len()).rev() {
                                if pieces.pieces[p].0 == 1 {
                                    self.push_piece(&pieces, p, k + 1);
                                }
                            }
                            self.bufs.pieces = pieces;
                            return;
                        }
                    }
                }
            }
        }
    }

    /// Coordinates in the plane of a face with unit `normal` (or zero),
    /// in which pieces are told from holes.
    pub(super) fn face_basis(&self, normal: DVec3) -> (DVec3, DVec3) {
        plane_basis(if normal == DVec3::ZERO {
            self.n
        } else {
            normal
        })
    }

    pub(super) fn classify(&self, k: usize) -> Side {
        let mut neg = false;
        let mut pos = false;
        for c in &self.bufs.cur.corners {
            let s = self.dist(c.v, k);
            neg |= s < -self.tol;
            pos |= s > self.tol;
        }
        match (neg, pos) {
            (true, true) => Side::Both,
            (true, false) => Side::Below,
            (false, true) => Side::Above,
            (false, false) => Side::On,
        }
    }

    pub(super) fn store_cur(&mut self, face: u32, part: usize) {
        let b = &mut self.bufs;
        let first = b.store_loops.len() as u32;
        for k in 0..b.cur.loops.len() {
            let l = b.cur.loop_slice(k);
            b.store_loops
                .push((b.store_corners.len() as u32, l.len() as u32));
            b.store_corners.extend_from_slice(l);
        }
        b.pieces_rec.push(PieceRec {
            face,
            first,
            count: b.cur.loops.len() as u32,
        });
        b.items
            .push((part as u32, Item::Piece(b.pieces_rec.len() as u32 - 1)));
    }

    pub(super) fn store_piece(&mut self, face: u32, pieces: &Pieces, p: usize, part: usize) {
        let b = &mut self.bufs;
        let first = b.store_loops.len() as u32;
        let mut count = 0;
        for l in pieces.piece_loops(p) {
            let c = pieces.corners_of(l);
            b.store_loops
                .push((b.store_corners.len() as u32, c.len() as u32));
            b.store_corners.extend_from_slice(c);
            count += 1;
        }
        b.pieces_rec.push(PieceRec { face, first, count });
        b.items
            .push((part as u32, Item::Piece(b.pieces_rec.len() as u32 - 1)));
    }

    pub(super) fn push_piece(&mut self, pieces: &Pieces, p: usize, k: usize) {
        let s = &mut self.bufs.stack;
        let first = s.loops.len() as u32;
        for l in pieces.piece_loops(p) {
            let c = pieces.corners_of(l);
            s.loops.push((s.corners.len() as u32, c.len() as u32));
            s.corners.extend_from_slice(c);
        }
        s.polys
            .push((first, s.loops.len() as u32 - first, k as u32));
    }
}
