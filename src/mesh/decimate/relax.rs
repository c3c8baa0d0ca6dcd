//! Between rounds of collapses: each free vertex moves towards the centre of its neighbours, onto
//! the surface and then balanced against its faces' sag, where that keeps its faces within the
//! error bound and passes the collapse's geometric and crossing checks. Greedy collapses stop with
//! triangles of uneven size; evening them out frees collapses the bound refused.

use super::{min_angle, Kind, State};
use glam::DVec3;

impl State<'_> {
    /// One sweep over the free vertices; how many moved.
    pub(super) fn relax(&mut self) -> usize {
        let mut moved = 0;
        for v in 0..self.pos.len() as u32 {
            if self.kind[v as usize] == Kind::Free
                && !self.faces_of[v as usize].is_empty()
                && self.relax_one(v)
            {
                moved += 1;
            }
        }
        moved
    }

    fn relax_one(&mut self, v: u32) -> bool {
        let smallest = self.fan_min_angle(v);
        self.move_toward_centre(v, self.options.min_angle_deg.to_radians().min(smallest), 1.0)
    }

    /// The smallest angle of the faces around `v`.
    pub(super) fn fan_min_angle(&self, v: u32) -> f64 {
        self.faces_of[v as usize].iter().map(|&f| min_angle(&self.corners(f))).fold(f64::INFINITY, f64::min)
    }

    /// Moves `v` the fraction `step` of the way to its neighbours' centre, onto the surface and
    /// balanced against its faces' sag, where no face around it gets an angle under `floor` and
    /// the move passes the collapse's checks. Whether it moved.
    pub(super) fn move_toward_centre(&mut self, v: u32, floor: f64, step: f64) -> bool {
        let ring = self.neighbours(v);
        let mean = ring.iter().map(|&w| self.pos[w as usize]).sum::<DVec3>() / ring.len() as f64;
        let centre = self.pos[v as usize] + step * (mean - self.pos[v as usize]);
        let Some((offset, normal)) = self.signed_distance(centre) else { return false };
        let on_surface = centre - offset * normal;
        let fan: Vec<(u32, [u32; 3])> =
            self.faces_of[v as usize].iter().map(|&f| (f, self.tris[f as usize])).collect();
        let old: Vec<[DVec3; 3]> = fan.iter().map(|&(f, _)| self.corners(f)).collect();
        let Some(corners) = self.reshaped(&fan, v, on_surface, floor) else { return false };
        let p = self.balanced(on_surface, &corners);
        let Some(corners) = self.reshaped(&fan, v, p, floor) else { return false };
        let error =
            |state: &Self, p: DVec3, faces: &[[DVec3; 3]]| state.face_distance(faces).max(state.distance(p));
        let before = error(self, self.pos[v as usize], &old);
        // Within the bound is enough: the point is evening the triangles out, not the error.
        if error(self, p, &corners) > self.options.max_error.unwrap_or(before).max(before) {
            return false;
        }
        if self.crosses(&fan, &corners, &[]) {
            return false;
        }
        self.pos[v as usize] = p;
        self.moved[v as usize] = true;
        for &(f, _) in &fan {
            self.insert_face(f);
        }
        true
    }
}
