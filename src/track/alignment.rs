//! Horizontal alignment: tangents, clothoid transitions and circular curves.
//!
//! Curvature is piecewise linear in `s` (constant on tangents and curves, linear on clothoid
//! transitions), so the heading is piecewise quadratic and known in closed form; the plane
//! position is its integral, evaluated with Gauss–Legendre quadrature from tabulated nodes.
//! Sign conventions (assets/docs/conventions.md): curvature is positive for a curve to the **left**; the signed
//! cant is positive when the **left** rail is higher (a right-hand curve raises the left rail).

/// Direction of a curve seen in the running direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Turn {
    /// Curve to the left: the right rail is the outer rail.
    Left,
    /// Curve to the right: the left rail is the outer rail.
    Right,
}

/// What a section is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SectionKind {
    /// Straight track, no cant.
    Tangent,
    /// Clothoid: curvature and cant ramp linearly between the neighbouring sections.
    Transition,
    /// Circular curve.
    Curve {
        /// Radius, m.
        radius: f64,
        /// Cant (height of the outer rail over the inner), m.
        cant: f64,
        /// Direction.
        turn: Turn,
    },
}

/// One section of the horizontal alignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Distance along the track where the section starts, m.
    pub start: f64,
    /// Length, m.
    pub length: f64,
    /// What it is.
    pub kind: SectionKind,
}

impl Section {
    /// Distance along the track where the section ends, m.
    pub fn end(&self) -> f64 {
        self.start + self.length
    }

    /// Signed curvature (1/m, positive to the left) and signed cant (m, positive when the left
    /// rail is higher) of a tangent or curve; `None` for a transition.
    fn constant_state(&self) -> Option<(f64, f64)> {
        match self.kind {
            SectionKind::Tangent => Some((0.0, 0.0)),
            SectionKind::Transition => None,
            SectionKind::Curve { radius, cant, turn } => Some(match turn {
                Turn::Left => (1.0 / radius, -cant),
                Turn::Right => (-1.0 / radius, cant),
            }),
        }
    }

    /// Balance (equilibrium) speed `V_eq = sqrt(g·R·h/s)` of a curve, m/s; `None` otherwise.
    pub fn balance_speed(&self, rail_spacing: f64) -> Option<f64> {
        match self.kind {
            SectionKind::Curve { radius, cant, .. } => {
                Some((crate::GRAVITY * radius * cant / rail_spacing).sqrt())
            }
            _ => None,
        }
    }
}

/// Unbalanced lateral acceleration in the track plane `a_nc = V²/R − g·h/s`, m/s².
pub fn cant_deficiency_acceleration(speed: f64, radius: f64, cant: f64, rail_spacing: f64) -> f64 {
    speed * speed / radius - crate::GRAVITY * cant / rail_spacing
}

/// Linear pieces of curvature and cant: on `[s0, s1]` the value goes from `k0` to `k1`.
#[derive(Debug, Clone, Copy)]
struct Piece {
    s0: f64,
    s1: f64,
    k0: f64,
    k1: f64,
    c0: f64,
    c1: f64,
    /// Heading at `s0`, rad.
    heading0: f64,
}

impl Piece {
    fn frac(&self, s: f64) -> f64 {
        ((s - self.s0) / (self.s1 - self.s0)).clamp(0.0, 1.0)
    }
    fn curvature(&self, s: f64) -> f64 {
        self.k0 + (self.k1 - self.k0) * self.frac(s)
    }
    fn cant(&self, s: f64) -> f64 {
        self.c0 + (self.c1 - self.c0) * self.frac(s)
    }
    fn heading(&self, s: f64) -> f64 {
        let d = s - self.s0;
        let dk = (self.k1 - self.k0) / (self.s1 - self.s0);
        self.heading0 + self.k0 * d + 0.5 * dk * d * d
    }
}

/// Evaluated horizontal alignment.
#[derive(Debug, Clone)]
pub struct Alignment {
    pieces: Vec<Piece>,
    /// Position nodes `(s, x, y)` every ≤ 1 m, used as integration starts.
    nodes: Vec<(f64, f64, f64)>,
    /// Unit tangent `(cos θ, sin θ)` at each node.
    tangents: Vec<(f64, f64)>,
    /// `lookup[k]`: the last node at or before `s = k` metres, where the search for a node
    /// starts (the run asks for positions a hundred thousand times a second).
    lookup: Vec<u32>,
}

/// 5-point Gauss–Legendre abscissae and weights on [-1, 1].
const GL5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

impl Alignment {
    /// Builds the alignment from validated sections (contiguous, starting at 0).
    pub fn new(sections: &[Section]) -> Self {
        let mut pieces = Vec::with_capacity(sections.len());
        let mut heading = 0.0;
        for (i, sec) in sections.iter().enumerate() {
            let (k0, c0, k1, c1) = match sec.constant_state() {
                Some((k, c)) => (k, c, k, c),
                None => {
                    // A transition ramps from the end of the previous section to the start of
                    // the next; a missing neighbour counts as tangent.
                    let prev = i
                        .checked_sub(1)
                        .and_then(|j| sections[j].constant_state())
                        .unwrap_or((0.0, 0.0));
                    let next = sections
                        .get(i + 1)
                        .and_then(|s| s.constant_state())
                        .unwrap_or((0.0, 0.0));
                    (prev.0, prev.1, next.0, next.1)
                }
            };
            let p = Piece {
                s0: sec.start,
                s1: sec.end(),
                k0,
                k1,
                c0,
                c1,
                heading0: heading,
            };
            heading = p.heading(p.s1);
            pieces.push(p);
        }
        let mut a = Alignment {
            pieces,
            nodes: Vec::new(),
            tangents: Vec::new(),
            lookup: Vec::new(),
        };
        let (mut x, mut y) = (0.0, 0.0);
        a.nodes.push((0.0, 0.0, 0.0));
        for p in a.pieces.clone() {
            let n = crate::bounds::to_count(((p.s1 - p.s0) / 1.0).ceil().max(1.0));
            let h = (p.s1 - p.s0) / n as f64;
            for j in 0..n {
                let sa = p.s0 + j as f64 * h;
                let (dx, dy) = integrate_piece(&p, sa, sa + h);
                x += dx;
                y += dy;
                a.nodes.push((sa + h, x, y));
            }
        }
        a.tangents = a
            .nodes
            .iter()
            .map(|n| {
                let (sn, cs) = a.heading(n.0).sin_cos();
                (cs, sn)
            })
            .collect();
        let metres = crate::bounds::to_count(a.length().ceil());
        a.lookup = (0..=metres)
            .map(|k| (a.nodes.partition_point(|n| n.0 <= k as f64).max(1) - 1) as u32)
            .collect();
        a
    }

    /// Index of the last node at or before `s` (the first node when none is): the same
    /// index as a binary search over all nodes, found from the metre lookup by a short walk.
    #[inline]
    fn node_index(&self, s: f64) -> usize {
        let last = self.nodes.len() - 1;
        let k = if s > 0.0 { s as usize } else { 0 };
        let mut i = match self.lookup.get(k) {
            Some(&i) => i as usize,
            None => last,
        };
        while i < last && self.nodes[i + 1].0 <= s {
            i += 1;
        }
        while i > 0 && self.nodes[i].0 > s {
            i -= 1;
        }
        i
    }

    /// Total length, m.
    pub fn length(&self) -> f64 {
        self.pieces.last().map(|p| p.s1).unwrap_or(0.0)
    }

    fn piece(&self, s: f64) -> &Piece {
        let i = self.pieces.partition_point(|p| p.s1 < s);
        &self.pieces[i.min(self.pieces.len() - 1)]
    }

    /// Position `(x, y)`, heading, curvature and cant at `s`, the piece found once (what
    /// [`Alignment::position`], [`Alignment::heading`], [`Alignment::curvature`] and
    /// [`Alignment::cant`] give one by one, the same numbers).
    #[inline]
    pub fn at(&self, s: f64) -> (f64, f64, f64, f64, f64) {
        let (x, y) = self.position(s);
        let p = self.piece(s);
        (x, y, p.heading(s), p.curvature(s), p.cant(s))
    }

    /// Signed curvature at `s`, 1/m (positive to the left).
    pub fn curvature(&self, s: f64) -> f64 {
        self.piece(s).curvature(s)
    }

    /// Signed cant at `s`, m (positive when the left rail is higher).
    pub fn cant(&self, s: f64) -> f64 {
        self.piece(s).cant(s)
    }

    /// Heading of the centre line at `s`, rad (from the start direction, positive to the left).
    pub fn heading(&self, s: f64) -> f64 {
        self.piece(s).heading(s)
    }

    /// Plane position `(x, y)` of the centre line at `s`, m: cubic Hermite interpolation
    /// between the integrated nodes (≤ 1 m apart) with the exact tangent `(cos θ, sin θ)` at
    /// both ends. The error is of order `h⁴·κ³/384`: below 1e-12 m for any railway curve.
    #[inline]
    pub fn position(&self, s: f64) -> (f64, f64) {
        let i = self.node_index(s);
        if i + 1 >= self.nodes.len() {
            return self.position_exact(s);
        }
        let (s0, x0, y0) = self.nodes[i];
        let (s1, x1, y1) = self.nodes[i + 1];
        let h = s1 - s0;
        if h <= 0.0 {
            return (x0, y0);
        }
        let t = ((s - s0) / h).clamp(0.0, 1.0);
        let (cs0, sn0) = self.tangents[i];
        let (cs1, sn1) = self.tangents[i + 1];
        let (t2, t3) = (t * t, t * t * t);
        let (h00, h10, h01, h11) = (
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + t,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        );
        (
            h00 * x0 + h10 * h * cs0 + h01 * x1 + h11 * h * cs1,
            h00 * y0 + h10 * h * sn0 + h01 * y1 + h11 * h * sn1,
        )
    }

    /// Plane position by quadrature from the nearest node (the reference for
    /// [`Alignment::position`]).
    pub fn position_exact(&self, s: f64) -> (f64, f64) {
        let i = self.node_index(s);
        let (sn, xn, yn) = self.nodes[i];
        if s <= sn {
            return (xn, yn);
        }
        // Integrate from the node to s piece by piece (at most two pieces within 1 m).
        let (mut x, mut y) = (xn, yn);
        let mut a = sn;
        while a < s {
            let p = *self.piece(a + 1e-12);
            let b = s.min(p.s1);
            if b <= a {
                break;
            }
            let (dx, dy) = integrate_piece(&p, a, b);
            x += dx;
            y += dy;
            a = b;
        }
        (x, y)
    }
}

/// ∫ (cos θ, sin θ) ds over [a, b] within one piece (θ quadratic: 5-point Gauss is exact to
/// ~1e-12 m over 1 m for any railway curvature).
fn integrate_piece(p: &Piece, a: f64, b: f64) -> (f64, f64) {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    GL5.iter().fold((0.0, 0.0), |(x, y), &(t, w)| {
        let th = p.heading(mid + half * t);
        (x + w * half * th.cos(), y + w * half * th.sin())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The metre lookup finds the same node as a binary search over all nodes, on a track with
    /// pieces of uneven length (nodes closer than 1 m) and off both ends.
    #[test]
    fn node_lookup_equals_binary_search() {
        let mut start = 0.0;
        let mut sections = Vec::new();
        for (length, kind) in [
            (10.3, SectionKind::Tangent),
            (0.4, SectionKind::Transition),
            (
                37.7,
                SectionKind::Curve {
                    radius: 400.0,
                    cant: 0.1,
                    turn: Turn::Left,
                },
            ),
            (2.05, SectionKind::Transition),
            (5.0, SectionKind::Tangent),
        ] {
            sections.push(Section {
                start,
                length,
                kind,
            });
            start += length;
        }
        let a = Alignment::new(&sections);
        let mut s = -1.0;
        while s < a.length() + 2.0 {
            let expected = a.nodes.partition_point(|n| n.0 <= s).max(1) - 1;
            assert_eq!(a.node_index(s), expected, "s = {s}");
            s += 0.013;
        }
        for n in &a.nodes {
            assert_eq!(a.nodes[a.node_index(n.0)].0, n.0);
        }
    }
}
