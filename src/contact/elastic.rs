//! Elastic normal contact by strips: the wheel profile is cut into strips 0.5 mm wide along its
//! surface (so the steep flange gets as many per millimetre of surface as the tread);
//! each strip's vertical gap to its rail is tabulated with the contact table (at the table's
//! rigid height and roll), and in a run the wheel's actual approach gives each strip a
//! penetration `d_j = δ − φ'·y_j − g_j`. A strip carries `c_j·d_j` per unit width, with `c_j`
//! chosen so that a parabolic gap (constant curvatures) gives exactly Hertz's `N = K·δ^{3/2}`:
//! `∫ d ds = (4/3)·√(2R_y)·δ^{3/2}` over the penetrated width, so `c = K/((4/3)·√(2R_y))`
//! (`R_y = 1/(2B)` the relative lateral radius, `K` Hertz's constant for the strip's
//! curvatures). This is the semi-Hertzian strip idea of Ayasse and Chollet's STRIPES (2005)
//! and the virtual penetration of Kik and Piotrowski (1996) without its ε: the load grows
//! from zero wherever the gap closes, so the contact moves continuously from tread to flange
//! root to flank, and two separate penetrated zones are two contacts sharing the load
//! elastically, with no jump in the normal force when either appears or they merge.

use super::geometry::{ContactState, Side, WheelFrame, WheelsetGeometry};
use super::hertz::{HertzShape, Material};

/// Width of a strip along the wheel profile's surface, m.
pub const STRIP_WIDTH: f64 = 5e-4;
/// Each tabulated wheel also keeps the narrower window of strips with a gap below this (m):
/// while the wheel's approach stays below it, only that window can be penetrated.
const NARROW_GAP: f64 = 3e-4;
/// Strips whose gap at the rigid position exceeds this are not tabulated, m (far above any
/// approach: 0.3 mm vertically is a 100 kN flange contact at 70°).
pub const STRIP_GAP_MAX: f64 = 1.5e-3;

/// One strip of a wheel at a tabulated lateral shift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strip {
    /// Vertical gap to the rail at the table's rigid position, m (≥ 0).
    pub gap: f64,
    /// Contact angle, rad (as [`super::WheelContact::angle`]).
    pub angle: f64,
    /// Lateral position of the strip's contact point from the wheelset centre, m.
    pub y: f64,
    /// Height of the contact point relative to the wheelset centre, m.
    pub z: f64,
    /// Rolling radius, m.
    pub radius: f64,
    /// Normal load per metre of vertical penetration over `E/(1 − ν²)`, m (the strip width
    /// included).
    pub stiffness: f64,
    /// Hertz shape from the strip's curvatures (for the creep ellipse).
    pub hertz: HertzShape,
}

#[derive(Debug, Clone, Copy, Default)]
struct Window {
    /// Index of the first strip on the wheel profile grid.
    first: u32,
    /// Offset in the flat strip array.
    offset: u32,
    /// Number of strips.
    len: u32,
    /// Grid indices `[from, to)` of the strips with a gap below [`NARROW_GAP`].
    narrow: (u32, u32),
}

/// Centres and widths (across the track) of strips of equal surface length on a wheel
/// profile.
fn strip_grid(wheel: &super::profile::Profile) -> Vec<(f64, f64)> {
    let (lo, hi) = wheel.range();
    let fine = 1e-5;
    let n = ((hi - lo) / fine) as usize;
    let mut grid = Vec::new();
    let (mut start, mut arc) = (lo, 0.0);
    for i in 1..=n {
        let eta = lo + i as f64 * fine;
        let (_, w1, _) = wheel.eval(eta - 0.5 * fine);
        arc += fine * (1.0 + w1 * w1).sqrt();
        if arc >= STRIP_WIDTH || i == n {
            grid.push((0.5 * (start + eta), eta - start));
            start = eta;
            arc = 0.0;
        }
    }
    grid
}

/// The strips near contact of both wheels at every shift of a contact table.
#[derive(Debug, Clone, Default)]
pub struct StripTable {
    windows: Vec<[Window; 2]>,
    /// What a penetrated strip contributes, interpolated between tabulated shifts lane by
    /// lane: `[stiffness, angle, z, radius, curvature_sum, ma, mb, k_over_e]` (see [`Strip`]).
    strips: Vec<[f64; 8]>,
    /// Gap and lateral position of every strip, apart: the hot data of the search.
    gap_y: Vec<[f64; 2]>,
}

/// Where a wheel stands on a [`StripTable`]: between tabulated states `i` and `i + 1`
/// (fraction `t`), wheel `k` (0 left, 1 right), its centre `approach` below the table's rigid
/// height and rolled `roll` beyond the table's roll (m, rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripQuery {
    /// Tabulated state below the wheel's shift.
    pub i: usize,
    /// Fraction of the way to state `i + 1`.
    pub t: f64,
    /// Wheel: 0 left, 1 right.
    pub k: usize,
    /// Vertical approach of the wheelset centre below the table's rigid height, m.
    pub approach: f64,
    /// Roll beyond the table's, rad.
    pub roll: f64,
}

/// Running sums over the strips of the zone being walked: `N`, `N·y`, `dN/dδ`, and `N` times
/// each interpolated number of a strip (`[stiffness, angle, z, radius, curvature_sum, ma, mb,
/// k_over_e]`, as [`StripTable`] stores them).
#[derive(Debug, Clone, Copy, Default)]
struct ZoneSums {
    n: f64,
    ny: f64,
    k: f64,
    nq: [f64; 8],
}

/// The load of one penetrated zone of a wheel (one contact patch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchLoad {
    /// Elastic normal load, N.
    pub normal: f64,
    /// Normal stiffness `dN/dδ_vertical`, N/m.
    pub stiffness: f64,
    /// Load-weighted contact angle, rad.
    pub angle: f64,
    /// Load centre from the wheelset centre (lateral, vertical), m.
    pub y: f64,
    /// See `y`.
    pub z: f64,
    /// Load-weighted rolling radius, m.
    pub radius: f64,
    /// Load-weighted Hertz shape of the strips (for the creep ellipse; weighted so that it
    /// changes continuously as the patch moves over the profile's curvatures).
    pub hertz: HertzShape,
}

impl WheelsetGeometry {
    /// The strips of one wheel of a solved state whose gap is below [`STRIP_GAP_MAX`]: index
    /// of the first on the profile grid and the strips.
    /// Gaps of one wheel of a solved state at every strip of the grid.
    fn strip_gaps(
        &self,
        state: &ContactState,
        side: Side,
        grid: &[(f64, f64)],
    ) -> Vec<(f64, [f64; 3], f64)> {
        let frame = WheelFrame::new(state.yaw, state.roll);
        grid.iter()
            .map(|&(eta, _)| {
                let (g, p, r) = self.circle_gap(side, state.y, &frame, eta);
                ((g + state.z).max(0.0), p, r)
            })
            .collect()
    }

    /// Grid range of the strips of one wheel of a solved state whose gap is below
    /// [`STRIP_GAP_MAX`] (empty: `(0, 0)`).
    fn strip_range(&self, state: &ContactState, side: Side, grid: &[(f64, f64)]) -> (usize, usize) {
        let gaps = self.strip_gaps(state, side, grid);
        match gaps.iter().position(|g| g.0 < STRIP_GAP_MAX) {
            None => (0, 0),
            Some(first) => (
                first,
                gaps.iter()
                    .rposition(|g| g.0 < STRIP_GAP_MAX)
                    .unwrap_or(first)
                    + 1,
            ),
        }
    }

    /// The strips `range` of one wheel of a solved state.
    fn strips(
        &self,
        state: &ContactState,
        side: Side,
        grid: &[(f64, f64)],
        range: (usize, usize),
    ) -> Vec<Strip> {
        let unit = Material {
            young: 1.0,
            poisson: 0.0,
        };
        let s = side.sign();
        if range.1 <= range.0 {
            return Vec::new();
        }
        let gaps = self.strip_gaps(state, side, &grid[range.0..range.1]);
        let first = range.0;
        let last = range.1 - 1;
        (first..=last)
            .map(|j| {
                let (gap, p, r) = gaps[j - first];
                let (eta, width) = grid[j];
                let (_, slope, ym) = self.rail_surface(side, p[1]);
                let angle = (s * slope).atan();
                let (_, w1, w2) = self.wheel().eval(eta);
                let kw = -w2 / (1.0 + w1 * w1).powf(1.5);
                let kr = self.rail().curvature(ym);
                let hertz = HertzShape::new(0.5 * angle.cos() / r, 0.5 * (kw + kr));
                // K of N = K·δ^{3/2} for these curvatures, per unit E/(1 − ν²).
                let k = hertz.load_from_approach(1e-4, &unit) * 1e6;
                let r_y = 1.0 / (2.0 * (0.5 * (kw + kr)).max(1e-3));
                let c = k / (4.0 / 3.0 * (2.0 * r_y).sqrt());
                Strip {
                    gap,
                    angle,
                    y: p[1] - state.y,
                    z: p[2],
                    radius: r,
                    stiffness: c * width,
                    hertz,
                }
            })
            .collect()
    }
}

impl StripTable {
    /// Writes the table's numbers, in order, for the contact table's file
    /// ([`super::table_cache`]).
    pub(super) fn encode(&self, e: &mut super::codec::Encoder) {
        e.len(self.windows.len());
        for w in self.windows.iter().flatten() {
            for v in [w.first, w.offset, w.len, w.narrow.0, w.narrow.1] {
                e.u32(v);
            }
        }
        e.len(self.strips.len());
        for s in &self.strips {
            e.f64s(s);
        }
        for g in &self.gap_y {
            e.f64s(g);
        }
    }

    /// Reads what [`Self::encode`] wrote for `states` tabulated states; `None` where a window
    /// would reach past the strips (a file is never trusted to index).
    pub(super) fn decode(d: &mut super::codec::Decoder, states: usize) -> Option<Self> {
        let n = d.len_of(40)?;
        if n != states {
            return None;
        }
        let mut windows = Vec::with_capacity(n);
        for _ in 0..n {
            let mut pair = [Window::default(); 2];
            for w in &mut pair {
                *w = Window {
                    first: d.u32()?,
                    offset: d.u32()?,
                    len: d.u32()?,
                    narrow: (d.u32()?, d.u32()?),
                };
            }
            windows.push(pair);
        }
        let m = d.len_of(80)?;
        let mut strips = Vec::with_capacity(m);
        for _ in 0..m {
            strips.push(d.f64s::<8>()?);
        }
        let mut gap_y = Vec::with_capacity(m);
        for _ in 0..m {
            gap_y.push(d.f64s::<2>()?);
        }
        // Every index the lookups form (`offset + j − first` for `j` in the window, and the
        // narrow window inside it) must fit in u32 and land inside the strips.
        let fits = windows.iter().flatten().all(|w| {
            let (first, len, offset) = (u64::from(w.first), u64::from(w.len), u64::from(w.offset));
            first + len + offset <= u64::from(u32::MAX)
                && offset + len <= m as u64
                && first <= u64::from(w.narrow.0)
                && w.narrow.0 <= w.narrow.1
                && u64::from(w.narrow.1) <= first + len
        });
        fits.then_some(StripTable {
            windows,
            strips,
            gap_y,
        })
    }

    /// Tabulates the strips of both wheels for every state of a contact table.
    pub(super) fn build(geo: &WheelsetGeometry, states: &[ContactState]) -> Self {
        let mut table = StripTable::default();
        let grid = strip_grid(geo.wheel());
        let sides = [Side::Left, Side::Right];
        let ranges: Vec<[(usize, usize); 2]> = states
            .iter()
            .map(|st| sides.map(|side| geo.strip_range(st, side, &grid)))
            .collect();
        for (i, st) in states.iter().enumerate() {
            let mut w = [Window::default(); 2];
            for (k, side) in sides.into_iter().enumerate() {
                // Each state also keeps the strips its neighbours keep: on a steep flank a
                // strip's gap changes by a millimetre between grid points, and an interval
                // must see every strip that is near contact at either of its ends.
                let mut range = ranges[i][k];
                for n in [i.wrapping_sub(1), i + 1] {
                    if let Some(r) = ranges.get(n).map(|r| r[k])
                        && r.1 > r.0
                    {
                        range = if range.1 > range.0 {
                            (range.0.min(r.0), range.1.max(r.1))
                        } else {
                            r
                        };
                    }
                }
                let strips = geo.strips(st, side, &grid, range);
                let first = range.0 as u32;
                let near = |g: &&Strip| g.gap < NARROW_GAP;
                let from = strips.iter().position(|g| near(&g)).unwrap_or(0);
                let to = strips.iter().rposition(|g| near(&g)).map_or(0, |i| i + 1);
                w[k] = Window {
                    first,
                    offset: table.strips.len() as u32,
                    len: strips.len() as u32,
                    narrow: (first + from as u32, first + to as u32),
                };
                table.gap_y.extend(strips.iter().map(|g| [g.gap, g.y]));
                table.strips.extend(strips.iter().map(|g| {
                    let h = &g.hertz;
                    [
                        g.stiffness,
                        g.angle,
                        g.z,
                        g.radius,
                        h.curvature_sum,
                        h.ma,
                        h.mb,
                        h.k_over_e,
                    ]
                }));
            }
            table.windows.push(w);
        }
        table
    }

    /// Number of strips stored.
    pub fn len(&self) -> usize {
        self.strips.len()
    }

    /// Whether nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.strips.is_empty()
    }

    /// The penetrated zones of a wheel placed on the table as `at` says. Returns up to two
    /// patches (the deepest two zones; a third, rare, is added to the nearer) and the least
    /// gap (negative: the deepest penetration), m.
    pub fn patches(&self, at: &StripQuery, material: &Material) -> ([Option<PatchLoad>; 2], f64) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            return unsafe { self.patches_avx(at, material) };
        }
        self.patches_lanes(at, material)
    }

    /// [`StripTable::patches`] compiled for AVX: the strips' eight numbers four lanes at a
    /// time, the same operations in the same order (no FMA), so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn patches_avx(&self, at: &StripQuery, material: &Material) -> ([Option<PatchLoad>; 2], f64) {
        self.patches_lanes(at, material)
    }

    /// The body of [`StripTable::patches`], inlined into the portable and the AVX build.
    #[inline(always)]
    fn patches_lanes(&self, at: &StripQuery, material: &Material) -> ([Option<PatchLoad>; 2], f64) {
        let StripQuery {
            i,
            t,
            k,
            approach,
            roll,
        } = *at;
        let e_star = material.young / (1.0 - material.poisson * material.poisson);
        let (w0, w1) = (self.windows[i][k], self.windows[i + 1][k]);
        let mut j0 = w0.first.max(w1.first);
        let mut j1 = (w0.first + w0.len).min(w1.first + w1.len);
        // Strips outside both narrow windows have gaps above NARROW_GAP at both ends of the
        // interval: while the deepest possible penetration stays below that, skip them. The
        // penetration less the gap, `approach − roll·y`, is linear in y, and y runs
        // monotonically along the window: its largest value is at one of the window's ends.
        let y_at = |j: u32| {
            let ya = self.gap_y[(w0.offset + j - w0.first) as usize][1];
            let yb = self.gap_y[(w1.offset + j - w1.first) as usize][1];
            ya + t * (yb - ya)
        };
        let deepest = if j1 > j0 {
            (approach - roll * y_at(j0)).max(approach - roll * y_at(j1 - 1))
        } else {
            approach
        };
        if deepest < NARROW_GAP {
            j0 = j0.max(w0.narrow.0.min(w1.narrow.0));
            j1 = j1.min(w0.narrow.1.max(w1.narrow.1));
        }
        let mut out: [Option<PatchLoad>; 2] = [None, None];
        let mut least = f64::INFINITY;
        let mut acc = ZoneSums::default();
        let mut open = false;
        let close = |acc: &mut ZoneSums, open: &mut bool, out: &mut [Option<PatchLoad>; 2]| {
            if !std::mem::take(open) {
                return;
            }
            let a = std::mem::take(acc);
            if a.n <= 0.0 {
                return;
            }
            let hertz = HertzShape {
                curvature_sum: a.nq[4] / a.n,
                ma: a.nq[5] / a.n,
                mb: a.nq[6] / a.n,
                k_over_e: a.nq[7] / a.n,
            };
            let p = PatchLoad {
                normal: a.n * e_star,
                stiffness: a.k * e_star,
                angle: a.nq[1] / a.n,
                y: a.ny / a.n,
                z: a.nq[2] / a.n,
                radius: a.nq[3] / a.n,
                hertz,
            };
            if out[0].is_none() {
                out[0] = Some(p);
            } else if out[1].is_none() {
                out[1] = Some(p);
            } else {
                // A third zone: fold it into the nearer one.
                let near = |q: &Option<PatchLoad>| q.map_or(f64::INFINITY, |q| (q.y - p.y).abs());
                let idx = if near(&out[0]) < near(&out[1]) { 0 } else { 1 };
                if let Some(q) = out[idx].as_mut() {
                    let n = q.normal + p.normal;
                    let mix = |x: f64, y: f64| (x * q.normal + y * p.normal) / n;
                    q.angle = mix(q.angle, p.angle);
                    q.y = mix(q.y, p.y);
                    q.z = mix(q.z, p.z);
                    q.radius = mix(q.radius, p.radius);
                    q.normal = n;
                    q.stiffness += p.stiffness;
                }
            }
        };
        // Two passes per chunk of strips: the interpolated lateral position and penetration of
        // each (a tight loop over contiguous gaps), then the sums over the penetrated ones.
        const CHUNK: usize = 32;
        let count = j1.saturating_sub(j0) as usize;
        let ia0 = (w0.offset + j0.min(j1) - w0.first) as usize;
        let ib0 = (w1.offset + j0.min(j1) - w1.first) as usize;
        let (mut ys, mut ds) = ([0.0; CHUNK], [0.0; CHUNK]);
        for start in (0..count).step_by(CHUNK) {
            let len = CHUNK.min(count - start);
            let ga = &self.gap_y[ia0 + start..ia0 + start + len];
            let gb = &self.gap_y[ib0 + start..ib0 + start + len];
            for m in 0..len {
                let ([ga, ya], [gb, yb]) = (ga[m], gb[m]);
                let y = ya + t * (yb - ya);
                ys[m] = y;
                ds[m] = approach - roll * y - (ga + t * (gb - ga));
            }
            let (sa, sb) = (
                &self.strips[ia0 + start..ia0 + start + len],
                &self.strips[ib0 + start..ib0 + start + len],
            );
            let mut m = 0;
            while m < len {
                if ds[m] <= 0.0 {
                    // `least.min(-d)` without its NaN handling on the critical path (the same
                    // value: a NaN `d` leaves `least` as it was either way).
                    if -ds[m] < least {
                        least = -ds[m];
                    }
                    close(&mut acc, &mut open, &mut out);
                    m += 1;
                    continue;
                }
                // A run of penetrated strips (a NaN penetration too, which poisons the sums
                // as it should), summed in registers.
                let mut z = acc;
                loop {
                    let (y, d) = (ys[m], ds[m]);
                    if -d < least {
                        least = -d;
                    }
                    let (a, b) = (&sa[m], &sb[m]);
                    // Lane by lane `a + t·(b − a)`, as the scalar interpolation wrote it.
                    let q: [f64; 8] = std::array::from_fn(|l| a[l] + t * (b[l] - a[l]));
                    let n = q[0] * d;
                    z.n += n;
                    z.ny += n * y;
                    z.k += q[0];
                    // All eight lanes (the first, N·stiffness, unused) so that they go as two
                    // vectors of four.
                    for (s, q) in z.nq.iter_mut().zip(q) {
                        *s += n * q;
                    }
                    m += 1;
                    if m == len || ds[m] <= 0.0 {
                        break;
                    }
                }
                acc = z;
                open = true;
            }
        }
        close(&mut acc, &mut open, &mut out);
        (out, least)
    }
}

#[cfg(test)]
mod tests {
    /// The AVX build of the strip sums gives the portable build's patches to the last bit,
    /// over the table's shifts (both wheels, between tabulated states), approaches from a
    /// touch to a flange contact and rolls either way.
    #[test]
    fn the_vector_build_gives_the_portable_patches_to_the_last_bit() {
        let v = crate::vehicle::Vehicle::load("vehicles/c80.toml".as_ref()).unwrap();
        let table = v.contact.table();
        let material = v.contact.model().material;
        let strips = table.strips();
        let mut loaded = 0;
        for y in (-40..=40).map(|k| k as f64 * 2.7e-4) {
            let (i, t) = table.locate(y);
            for k in 0..2 {
                for approach in [2e-5, 1e-4, 3.5e-4, 8e-4] {
                    for roll in [-2e-3, 0.0, 1.5e-3] {
                        let at = super::StripQuery {
                            i,
                            t,
                            k,
                            approach,
                            roll,
                        };
                        let fast = strips.patches(&at, &material);
                        let portable = strips.patches_lanes(&at, &material);
                        assert_eq!(
                            format!("{fast:?}"),
                            format!("{portable:?}"),
                            "y {y}, wheel {k}, approach {approach}, roll {roll}"
                        );
                        loaded += fast.0.iter().flatten().count();
                    }
                }
            }
        }
        assert!(loaded > 500, "only {loaded} patches loaded");
    }
}
