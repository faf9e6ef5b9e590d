//! The lattice sums: class sums `S[r] = Σ_{j ≡ r (mod 4)} E(j)` (and the
//! weighted sums `Σ j_k E`, `Σ j_k j_l E` for derivatives) over the ellipsoid
//! `Q(j/2 + w_r) < R²/π`, with the normalised terms
//!
//! ```text
//! E(j) = exp( iπ/4 jᵀτ'j + iπ jᵀz_r + π w_rᵀ Y w_r ),   |E(j)| = exp(-π Q(j/2 + w_r)).
//! ```
//!
//! Terms come from multiplicative recurrences: along the inner coordinate
//! `E(j + e_g) = E(j) A(j)`, `A(j + e_g) = A(j) exp(iπ τ'_gg / 2)`, so a term costs
//! two complex products and no exponential.

use super::{ThetaPlan, Workspace};
use crate::error::Result;
use crate::numeric::cancel::Cancel;
use num_complex::Complex64;

type C = Complex64;

/// Rows of a lattice sum between two checks for cancellation: 64 rows are
/// ~3 µs of the genus-2 walk and ~30 µs of the generic path, so the check
/// (~50 ns) costs nothing and a single point summed for a second (the cost
/// cap, `MAX_SECONDS_PER_POINT`) still stops within the 0.5 s promised.
const ROWS_PER_CHECK: u32 = 64;

/// Counts a row and checks `cancel` every [`ROWS_PER_CHECK`] rows.
#[inline(always)]
fn poll(ws: &mut Workspace, cancel: Option<&Cancel>) -> Result<()> {
    if let Some(c) = cancel {
        ws.rows = ws.rows.wrapping_add(1);
        if ws.rows % ROWS_PER_CHECK == 0 {
            c.check()?;
        }
    }
    Ok(())
}

impl ThetaPlan {
    /// `iπ/4 jᵀτ'j + iπ jᵀz_r + π w_rᵀYw_r`, real part written as `-π Q(j/2 + w_r)`
    /// so that it is computed without cancellation.
    fn log_term(&self, j: &[i64], zr: &[C], wr: &[f64]) -> C {
        let g = self.g;
        let mut re = 0.0;
        let mut im = 0.0;
        for i in 0..g {
            let ui = 0.5 * j[i] as f64 + wr[i];
            let ji = j[i] as f64;
            for k in 0..g {
                let uk = 0.5 * j[k] as f64 + wr[k];
                re -= self.y[i * g + k] * ui * uk;
                im += 0.25 * self.x[i * g + k] * ji * j[k] as f64;
            }
            im += ji * zr[i].re;
        }
        let pi = std::f64::consts::PI;
        C::new(pi * re, pi * im)
    }

    /// `E(j + e_k)/E(j) = exp(iπ/4 τ'_kk (2 j_k + 1) + iπ/2 Σ_{l≠k} τ'_kl j_l + iπ z_k)`.
    fn ratio(&self, k: usize, j: &[i64], zr: &[C]) -> C {
        let g = self.g;
        let mut s = 0.25 * self.tau[k * g + k] * (2.0 * j[k] as f64 + 1.0) + zr[k];
        for l in 0..g {
            if l != k {
                s += 0.5 * self.tau[k * g + l] * j[l] as f64;
            }
        }
        (C::i() * std::f64::consts::PI * s).exp()
    }

    /// Genus 2: walk a cursor `(j1, k)` along the row centres, carrying `E`,
    /// `A = E(j1,k+1)/E(j1,k)`, `Ainv = E(j1,k-1)/E(j1,k)` and the row-step ratio,
    /// all updated by constant factors `q_kl = exp(iπ τ'_kl/2)`; each row is then
    /// swept up and down from its centre. Starting at the centre of the
    /// ellipsoid keeps the one directly computed term (and its phase) small.
    ///
    /// The hot loop of the per-point path; its steps ([`G2Rows`],
    /// [`ThetaPlan::walk_g2`], [`row_sums`], [`add_row`]) are inlined into it.
    pub(super) fn sum_g2<const ORDER: usize>(
        &self,
        zr: &[C],
        wr: &[f64],
        ws: &mut Workspace,
        cancel: Option<&Cancel>,
    ) -> Result<()> {
        let mut buf = [(0i64, 1i64, 0i64); G2_MAX_ROWS];
        let rows = G2Rows::new(self, wr, &mut buf);
        let j1c = rows.geom.j1c;
        let q11 = self.qmat[0];
        let kc = round_i64(rows.row(j1c).0);
        let start = [j1c, kc];
        let e0 = self.log_term(&start, zr, wr).exp();
        let a0 = self.ratio(1, &start, zr);
        let bup = self.ratio(0, &start, zr);
        let up = G2Cursor {
            j1: j1c,
            k: kc,
            e: e0,
            a: a0,
            ainv: self.qmat[3] / a0,
            bs: bup,
        };
        let mut down = G2Cursor {
            bs: q11 / bup,
            ..up
        };
        // the first row of the downward pass is j1c - 1
        down.next_row(q11, self.qinv[1], self.qmat[1], -1);
        // Without a token the walk has no poll at all: the check per row cost
        // ~2.5 % of a single genus-2 point.
        if cancel.is_some() {
            self.walk_g2::<ORDER, true>(1, &rows, up, ws, cancel)?;
            self.walk_g2::<ORDER, true>(-1, &rows, down, ws, cancel)
        } else {
            self.walk_g2::<ORDER, false>(1, &rows, up, ws, None)?;
            self.walk_g2::<ORDER, false>(-1, &rows, down, ws, None)
        }
    }

    /// One pass of [`ThetaPlan::sum_g2`] over the rows from the cursor's on,
    /// upward (`dir = 1`) or downward (`dir = -1`); `POLL`: check `cancel`
    /// every [`ROWS_PER_CHECK`] rows.
    #[inline(always)]
    fn walk_g2<const ORDER: usize, const POLL: bool>(
        &self,
        dir: i64,
        rows: &G2Rows,
        mut cur: G2Cursor,
        ws: &mut Workspace,
        cancel: Option<&Cancel>,
    ) -> Result<()> {
        let (q11, q12, q22) = (self.qmat[0], self.qmat[1], self.qmat[3]);
        let (q12i, q22i) = (self.qinv[1], self.qinv[3]);
        let (q12s, q12si) = if dir == 1 { (q12, q12i) } else { (q12i, q12) };
        let (j1min, j1max) = (rows.geom.j1min, rows.geom.j1max);
        while (dir == 1 && cur.j1 <= j1max) || (dir == -1 && cur.j1 >= j1min) {
            if POLL {
                poll(ws, cancel)?;
            }
            let (target, lo, hi) = rows.bounds(cur.j1);
            if lo <= hi {
                while cur.k < target {
                    cur.e *= cur.a;
                    cur.a *= q22;
                    cur.ainv *= q22i;
                    cur.bs *= q12s;
                    cur.k += 1;
                }
                while cur.k > target {
                    cur.e *= cur.ainv;
                    cur.a *= q22i;
                    cur.ainv *= q22;
                    cur.bs *= q12si;
                    cur.k -= 1;
                }
                let r = row_sums::<ORDER>(cur.e, cur.a, cur.ainv, q22, cur.k, lo, hi);
                add_row::<ORDER>(ws, cur.j1, &r);
            }
            cur.next_row(q11, q12s, q12si, dir);
        }
        Ok(())
    }

    /// Any genus: enumerate the outer coordinates `j_1..j_{g-1}` over the
    /// ellipsoid (Fincke–Pohst style, from the factorisation of `Q`); each inner
    /// row starts from a directly computed term at its lower end and is swept
    /// upward with the recurrence (no division, so no overflow for large `Im τ`).
    pub(super) fn sum_generic<const ORDER: usize>(
        &self,
        zr: &[C],
        wr: &[f64],
        ws: &mut Workspace,
        cancel: Option<&Cancel>,
    ) -> Result<()> {
        let mut j = [0i64; super::MAX_GENUS];
        self.level::<ORDER>(0, 0.0, &mut j[..self.g], zr, wr, ws, cancel)
    }

    #[allow(clippy::too_many_arguments)]
    fn level<const ORDER: usize>(
        &self,
        i: usize,
        partial: f64,
        j: &mut [i64],
        zr: &[C],
        wr: &[f64],
        ws: &mut Workspace,
        cancel: Option<&Cancel>,
    ) -> Result<()> {
        poll(ws, cancel)?;
        let g = self.g;
        let rem = self.rq - partial;
        if rem < 0.0 {
            return Ok(());
        }
        let t: f64 = (0..i)
            .map(|k| self.ldl_l[i * g + k] * (0.5 * j[k] as f64 + wr[k]))
            .sum();
        let h = (rem / self.ldl_d[i]).sqrt();
        let lo = ceil_i64(2.0 * (-t - h - wr[i]));
        let hi = floor_i64(2.0 * (-t + h - wr[i]));
        if i + 1 < g {
            for v in lo..=hi {
                j[i] = v;
                let dv = 0.5 * v as f64 + wr[i] + t;
                let part = partial + self.ldl_d[i] * dv * dv;
                self.level::<ORDER>(i + 1, part, j, zr, wr, ws, cancel)?;
            }
            return Ok(());
        }
        if lo > hi {
            return Ok(());
        }
        j[i] = lo;
        let mut e = self.log_term(j, zr, wr).exp();
        let mut a = self.ratio(i, j, zr);
        let q = self.qmat[i * g + i];
        let mut r0 = [C::new(0.0, 0.0); 4];
        let mut r1 = [C::new(0.0, 0.0); 4];
        let mut r2 = [C::new(0.0, 0.0); 4];
        for v in lo..=hi {
            let cls = (v & 3) as usize;
            r0[cls] += e;
            if ORDER >= 1 {
                let vf = v as f64;
                r1[cls] += e * vf;
                if ORDER >= 2 {
                    r2[cls] += e * (vf * vf);
                }
            }
            e *= a;
            a *= q;
        }
        let mut base = 0usize;
        for &jk in &j[..g - 1] {
            base = 4 * (base + (jk & 3) as usize);
        }
        for cls in 0..4 {
            let r = base + cls;
            ws.s0[r] += r0[cls];
            if ORDER >= 1 {
                for k in 0..g - 1 {
                    ws.s1[r * g + k] += r0[cls] * j[k] as f64;
                }
                ws.s1[r * g + g - 1] += r1[cls];
                if ORDER >= 2 {
                    for k in 0..g - 1 {
                        for l in 0..g - 1 {
                            ws.s2[(r * g + k) * g + l] += r0[cls] * (j[k] as f64 * j[l] as f64);
                        }
                        let mixed = r1[cls] * j[k] as f64;
                        ws.s2[(r * g + k) * g + g - 1] += mixed;
                        ws.s2[(r * g + g - 1) * g + k] += mixed;
                    }
                    ws.s2[(r * g + g - 1) * g + g - 1] += r2[cls];
                }
            }
        }
        Ok(())
    }
}

/// The rows of the genus-2 ellipsoid `Q(j/2 + w_r) < R²/π`: the range of
/// `j1`, the start row, and per row the cursor target and the range of `j2`.
///
/// The table of row bounds lives in the caller's frame (`table`, borrowed):
/// held by value it made this struct 2.3 kB, returned and copied with two
/// `memcpy` calls per theta evaluation (+11 % on a single genus-2 point).
struct G2Rows<'t> {
    geom: G2Geometry,
    /// `bounds_of(j1min + r)`, when there are at most [`G2_MAX_ROWS`] rows
    /// (else empty: computed per row).
    table: &'t [(i64, i64, i64)],
}

/// The scalars of [`G2Rows`].
#[derive(Clone, Copy)]
struct G2Geometry {
    rq: f64,
    d1: f64,
    d2: f64,
    l21: f64,
    w: [f64; 2],
    j1min: i64,
    j1max: i64,
    j1c: i64,
}

/// Rows are short (~10 terms): computing all bounds first lets the square
/// roots overlap instead of sitting on each row's critical path.
const G2_MAX_ROWS: usize = 96;

impl<'t> G2Rows<'t> {
    #[inline(always)]
    fn new(
        plan: &ThetaPlan,
        wr: &[f64],
        buf: &'t mut [(i64, i64, i64); G2_MAX_ROWS],
    ) -> G2Rows<'t> {
        let (d1, d2, l21) = (plan.ldl_d[0], plan.ldl_d[1], plan.ldl_l[2]);
        let rq = plan.rq;
        let h1 = (rq / d1).sqrt();
        let j1min = ceil_i64(2.0 * (-h1 - wr[0]));
        let j1max = floor_i64(2.0 * (h1 - wr[0]));
        let j1c = round_i64(-2.0 * wr[0]).clamp(j1min.min(j1max), j1max.max(j1min));
        let nrows = (j1max - j1min + 1).max(0) as usize;
        let geom = G2Geometry {
            rq,
            d1,
            d2,
            l21,
            w: [wr[0], wr[1]],
            j1min,
            j1max,
            j1c,
        };
        let table: &[(i64, i64, i64)] = if nrows <= G2_MAX_ROWS {
            for (r, slot) in buf[..nrows].iter_mut().enumerate() {
                *slot = geom.bounds_of(j1min + r as i64);
            }
            &buf[..nrows]
        } else {
            &[]
        };
        G2Rows { geom, table }
    }

    #[inline(always)]
    fn row(&self, j1: i64) -> (f64, f64) {
        self.geom.row(j1)
    }

    #[inline(always)]
    fn bounds(&self, j1: i64) -> (i64, i64, i64) {
        if !self.table.is_empty() {
            self.table[(j1 - self.geom.j1min) as usize]
        } else {
            self.geom.bounds_of(j1)
        }
    }
}

impl G2Geometry {
    /// Centre and half-width (in `j2` units) of row `j1`; a negative width for
    /// a row outside the ellipsoid.
    #[inline(always)]
    fn row(&self, j1: i64) -> (f64, f64) {
        let u1 = 0.5 * j1 as f64 + self.w[0];
        let rem = self.rq - self.d1 * u1 * u1;
        let c = 2.0 * (-self.l21 * u1 - self.w[1]);
        (
            c,
            if rem >= 0.0 {
                2.0 * (rem / self.d2).sqrt()
            } else {
                -1.0
            },
        )
    }

    /// (cursor target, lo, hi) of row `j1`; empty rows have `lo > hi`.
    #[inline(always)]
    fn bounds_of(&self, j1: i64) -> (i64, i64, i64) {
        let (c, hw) = self.row(j1);
        if hw < 0.0 {
            (0, 1, 0)
        } else {
            (round_i64(c), ceil_i64(c - hw), floor_i64(c + hw))
        }
    }
}

/// The cursor of the genus-2 walk at `(j1, k)`: `E`, `A`, `Ainv` and the
/// row-step ratio `bs`.
#[derive(Clone, Copy)]
struct G2Cursor {
    j1: i64,
    k: i64,
    e: C,
    a: C,
    ainv: C,
    bs: C,
}

impl G2Cursor {
    /// Steps to row `j1 + dir` (same `k`).
    #[inline(always)]
    fn next_row(&mut self, q11: C, q12s: C, q12si: C, dir: i64) {
        self.e *= self.bs;
        self.bs *= q11;
        self.a *= q12s;
        self.ainv *= q12si;
        self.j1 += dir;
    }
}

/// The class sums of one row `lo ..= hi` with the cursor at `k` (term `e`,
/// ratios `a` up and `ainv` down): `r[0][c] = Σ E`, `r[1][c] = Σ j2 E`,
/// `r[2][c] = Σ j2² E` over `j2 ≡ c (mod 4)`. The upward sweep `k ..= hi`
/// and the downward sweep `k − 1 ..= lo` run interleaved: two independent
/// product chains hide the multiply latency.
#[inline(always)]
fn row_sums<const ORDER: usize>(
    e: C,
    a: C,
    ainv: C,
    q22: C,
    k: i64,
    lo: i64,
    hi: i64,
) -> [[C; 4]; 3] {
    let mut r0 = [C::new(0.0, 0.0); 4];
    let mut r1 = [C::new(0.0, 0.0); 4];
    let mut r2 = [C::new(0.0, 0.0); 4];
    if ORDER == 0 {
        // Unrolled by 4 so that the class of every term is static:
        // accu[i] collects offsets ≡ i (mod 4) from k, accd[i] from k-1 down.
        let (nu, nd) = (hi - k + 1, k - lo);
        let (mut tu, mut au) = (e, a);
        let (mut td, mut ad) = (e * ainv, ainv * q22);
        let mut accu = [C::new(0.0, 0.0); 4];
        let mut accd = [C::new(0.0, 0.0); 4];
        let both4 = (nu.min(nd).max(0) / 4) * 4;
        let mut i = 0;
        while i < both4 {
            for slot in 0..4 {
                accu[slot] += tu;
                accd[slot] += td;
                tu *= au;
                au *= q22;
                td *= ad;
                ad *= q22;
            }
            i += 4;
        }
        sweep_tail(&mut accu, tu, au, q22, nu - both4);
        sweep_tail(&mut accd, td, ad, q22, nd - both4);
        for slot in 0..4 {
            r0[((k + slot as i64) & 3) as usize] += accu[slot];
            r0[((k - 1 - slot as i64) & 3) as usize] += accd[slot];
        }
    } else {
        let (mut tu, mut au, mut ju) = (e, a, k);
        let (mut td, mut ad, mut jd) = (e * ainv, ainv * q22, k - 1);
        let both = (hi - k + 1).min(k - lo);
        for _ in 0..both {
            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, tu, ju);
            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, td, jd);
            tu *= au;
            au *= q22;
            td *= ad;
            ad *= q22;
            ju += 1;
            jd -= 1;
        }
        while ju <= hi {
            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, tu, ju);
            tu *= au;
            au *= q22;
            ju += 1;
        }
        while jd >= lo {
            accumulate::<ORDER>(&mut r0, &mut r1, &mut r2, td, jd);
            td *= ad;
            ad *= q22;
            jd -= 1;
        }
    }
    [r0, r1, r2]
}

/// Adds the class sums `r` of row `j1` ([`row_sums`]) to the workspace, with
/// the weights `j1`, `j1²`, `j1 j2` of the derivatives.
#[inline(always)]
fn add_row<const ORDER: usize>(ws: &mut Workspace, j1: i64, r: &[[C; 4]; 3]) {
    let [r0, r1, r2] = r;
    let base = ((j1 & 3) as usize) * 4;
    let j1f = j1 as f64;
    for cls in 0..4 {
        let r = base + cls;
        ws.s0[r] += r0[cls];
        if ORDER >= 1 {
            ws.s1[2 * r] += r0[cls] * j1f;
            ws.s1[2 * r + 1] += r1[cls];
            if ORDER >= 2 {
                ws.s2[4 * r] += r0[cls] * (j1f * j1f);
                let mixed = r1[cls] * j1f;
                ws.s2[4 * r + 1] += mixed;
                ws.s2[4 * r + 2] += mixed;
                ws.s2[4 * r + 3] += r2[cls];
            }
        }
    }
}

/// The rest of a sweep of `n` terms (any `n`; nothing for `n ≤ 0`) starting at
/// slot 0: `acc[i mod 4] += t_i`, `t_{i+1} = t_i a_i`, `a_{i+1} = a_i q`.
#[inline(always)]
fn sweep_tail(acc: &mut [C; 4], mut t: C, mut a: C, q: C, n: i64) {
    let mut i = 0;
    while i < n {
        acc[(i & 3) as usize] += t;
        t *= a;
        a *= q;
        i += 1;
    }
}

#[inline(always)]
fn accumulate<const ORDER: usize>(r0: &mut [C; 4], r1: &mut [C; 4], r2: &mut [C; 4], t: C, j: i64) {
    let cls = (j & 3) as usize;
    r0[cls] += t;
    if ORDER >= 1 {
        let jf = j as f64;
        r1[cls] += t * jf;
        if ORDER >= 2 {
            r2[cls] += t * (jf * jf);
        }
    }
}

/// `floor` without a libm call (the baseline x86-64 target has no `roundsd`);
/// exact for |x| < 2^62, which the caller guarantees (|x| is a few hundred).
#[inline(always)]
pub(super) fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    // branch-free: the comparison is data dependent (signs of reduced coordinates)
    t - i64::from((t as f64) > x)
}

/// `ceil` without a libm call, see [`floor_i64`].
#[inline(always)]
pub(super) fn ceil_i64(x: f64) -> i64 {
    -floor_i64(-x)
}

/// Nearest integer (ties up) without a libm call, see [`floor_i64`].
#[inline(always)]
pub(super) fn round_i64(x: f64) -> i64 {
    floor_i64(x + 0.5)
}
