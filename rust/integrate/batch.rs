//! Batch kernels for so(4): vector lanes carry different trajectories.
//!
//! The state of `W` trajectories is stored structure-of-arrays, `y[k][w]` =
//! component `k` of trajectory `w`, so every arithmetic operation of a step is
//! one `W`-wide vector operation. `W = 4` doubles fill an AVX2 register.
//!
//! **Same results as one trajectory at a time.** Every lane performs exactly the
//! floating-point operations of the single-trajectory stepper, in the same
//! order (Rust never contracts `a * b + c` into an FMA, and the so(4) field is
//! evaluated by the same expressions), so `integrate_many` is bit-for-bit equal
//! to `integrate` state by state (tests below and `tests/test_integrate.py`):
//!
//! - **gauss16** (`gauss16_group`): the step size sequence depends only on the
//!   sample times and `dt`, so the `W` lanes step in lockstep. Each lane keeps its
//!   own stopping rule of the stage iteration; a lane that has converged is
//!   masked (its stages are no longer written), and the group stops when the
//!   slowest lane has converged. Samples land on their times exactly, as for one
//!   trajectory. The 8 stages × 4 lanes are evaluated as 32 lanes of
//!   [`vector_field4_lanes`].
//! - **dop853** (`dop853_group`): each lane keeps its own time, step size, next
//!   sample and step count; a rejected step is masked by the per-lane control
//!   (the lane keeps its state and retries with a smaller step). A lane whose
//!   trajectory has reached its last sample is refilled with the next trajectory
//!   of the group, so lanes do not idle while a slower trajectory finishes.
//!   Samples are hit by shortening the step to the sample time, per lane, as in
//!   the single-trajectory method (no interpolation: a dense-output sample would
//!   differ from `integrate` by the interpolation error).
//!
//! **Dispatch.** The kernels are plain Rust on `[f64; W]` arrays written so that
//! LLVM vectorises them; each is compiled twice, for the baseline target (SSE2 on
//! x86-64) and with `#[target_feature(enable = "avx2,fma")]`, and the AVX2 copy
//! is chosen at run time with `is_x86_feature_detected!`. FMA is enabled for the
//! instruction set, but no FMA is emitted (it would change the rounding, and the
//! results would no longer match `integrate`).

// Index loops mirror the subscripts of the formulas (i, j stages; k components; w lanes).
#![allow(clippy::needless_range_loop)]

use super::dop853::{A as DA, B as DB, BHH, ER};
use super::gauss_tables::{B8, E8, MU8};
use super::{scaled, starting_step, substeps, StopRule};
use crate::cancel::Cancel;
use crate::error::{Error, Result};
use crate::so4::{vector_field4, vector_field4_lanes};

/// Trajectories per vector group (f64 lanes of an AVX2 register).
pub const W: usize = 4;
/// Stages of gauss16.
const S: usize = 8;
/// Stage × trajectory lanes of one gauss16 field evaluation.
const SW: usize = S * W;
/// so(4) state length.
const M: usize = 6;
/// Steps (gauss16) or step attempts (dop853) between two cancellation checks:
/// ~0.1 ms of work for a group.
const CHECK_EVERY: u32 = 64;

/// Runs `body` compiled for AVX2+FMA when the CPU has them, else the baseline.
macro_rules! dispatch {
    ($avx2:ident, $body:ident, ($($arg:expr),*)) => {{
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX2 and FMA (checked just above).
                return unsafe { $avx2($($arg),*) };
            }
        }
        $body($($arg),*)
    }};
}

/// gauss16 on up to `W` trajectories `y0s` (row-major, `rows · 6`) through
/// `times` with the step `dt`, writing `(rows, times.len(), 6)` into `out`;
/// returns the steps of one trajectory.
pub(super) fn gauss16_group(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    dispatch!(
        gauss16_group_avx2,
        gauss16_group_body,
        (c, y0s, t0, times, dt, out, cancel)
    )
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn gauss16_group_avx2(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    gauss16_group_body(c, y0s, t0, times, dt, out, cancel)
}

/// The state of a gauss16 lane group.
struct Gauss16Lanes {
    /// `y[k][w]`.
    y: [[f64; W]; M],
    /// Kahan compensation of the update, per component and lane.
    comp: [[f64; W]; M],
    /// `L[k][i·W + w] = h b_i f_k(Y_i)` of lane `w`.
    l: [[f64; SW]; M],
    last_h: f64,
}

#[inline(always)]
fn gauss16_group_body(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    dt: f64,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    let rows = y0s.len() / M;
    let per = times.len() * M;
    // Unused lanes hold the zero state: f(0) = 0, so their iteration stops at once.
    let mut g = Gauss16Lanes {
        y: [[0.0; W]; M],
        comp: [[0.0; W]; M],
        l: [[0.0; SW]; M],
        last_h: 0.0,
    };
    for (w, y0) in y0s.chunks_exact(M).enumerate() {
        for k in 0..M {
            g.y[k][w] = y0[k];
        }
    }
    let mut t = t0;
    let mut steps = 0u64;
    let mut since_check = 0u32;
    for (s, &tk) in times.iter().enumerate() {
        let span = tk - t;
        if span > 0.0 {
            let n = substeps(span, dt);
            let h = span / n;
            // n ≤ MAX_STEPS < 2^53 (checked by the caller), so the count is exact.
            for _ in 0..n as u64 {
                gauss16_step(c, &mut g, h)?;
                since_check += 1;
                if since_check == CHECK_EVERY {
                    since_check = 0;
                    cancel.check()?;
                }
            }
            steps += n as u64;
            t = tk;
        }
        for w in 0..rows {
            let o = &mut out[w * per + s * M..w * per + (s + 1) * M];
            for k in 0..M {
                o[k] = g.y[k][w];
            }
        }
    }
    Ok(steps)
}

/// One gauss16 step of size `h` on every lane; the operations of each lane are
/// those of `GaussFixed::<8, 6>::step`, in the same order.
#[inline(always)]
fn gauss16_step(c: &[f64; 6], g: &mut Gauss16Lanes, h: f64) -> Result<()> {
    let mut hb = [0.0; S];
    for i in 0..S {
        hb[i] = h * B8[i];
    }
    if !super::reuse_stages(g.last_h, h) {
        let mut f0 = [[0.0; W]; M];
        vector_field4_lanes(c, &g.y, &mut f0);
        for k in 0..M {
            for i in 0..S {
                for w in 0..W {
                    g.l[k][i * W + w] = hb[i] * f0[k][w];
                }
            }
        }
    } else if h == g.last_h {
        // Predictor (see GaussFixed): f at the new nodes from the previous
        // collocation polynomial, carried as L_j / b_j.
        for k in 0..M {
            let mut fj = [0.0; SW];
            for j in 0..S {
                for w in 0..W {
                    fj[j * W + w] = g.l[k][j * W + w] / B8[j];
                }
            }
            let mut acc = [0.0; SW];
            for j in 0..S {
                for i in 0..S {
                    let e = E8[i][j];
                    for w in 0..W {
                        acc[i * W + w] += e * fj[j * W + w];
                    }
                }
            }
            for i in 0..S {
                for w in 0..W {
                    g.l[k][i * W + w] = B8[i] * acc[i * W + w];
                }
            }
        }
    } else {
        let r = h / g.last_h;
        for lk in g.l.iter_mut() {
            for x in lk.iter_mut() {
                *x *= r;
            }
        }
    }
    g.last_h = h;
    let mut ymax = [0.0f64; W];
    for w in 0..W {
        for k in 0..M {
            ymax[w] = ymax[w].max(g.y[k][w].abs());
        }
    }
    let mut rules: [StopRule; W] = std::array::from_fn(|_| StopRule::new());
    let mut active = [true; W];
    let mut ys = [[0.0; SW]; M];
    let mut fs = [[0.0; SW]; M];
    // Each lane's stages as they were when its iteration stopped: the lanes keep
    // iterating (unmasked stores are cheaper than masked ones), and the saved
    // stages are restored at the end, so every lane ends exactly where a
    // single-trajectory step would.
    let mut saved = [[0.0; SW]; M];
    loop {
        // Y_i = y + Σ_j μ_ij L_j for every stage and lane.
        for k in 0..M {
            let mut acc = [0.0; SW];
            for i in 0..S {
                acc[i * W..(i + 1) * W].copy_from_slice(&g.y[k]);
            }
            for j in 0..S {
                for i in 0..S {
                    let mu = MU8[i][j];
                    for w in 0..W {
                        acc[i * W + w] += mu * g.l[k][j * W + w];
                    }
                }
            }
            ys[k] = acc;
        }
        vector_field4_lanes(c, &ys, &mut fs);
        // Largest increment per stage and lane (independent accumulators). The
        // maximum is exact and `d > m` skips NaN as f64::max does, so the result
        // is that of the single-trajectory stepper.
        let mut dm = [0.0f64; SW];
        for k in 0..M {
            for x in 0..SW {
                let new = hb[x / W] * fs[k][x];
                let d = (new - g.l[k][x]).abs();
                dm[x] = if d > dm[x] { d } else { dm[x] };
                g.l[k][x] = new;
            }
        }
        let mut any = false;
        for w in 0..W {
            if !active[w] {
                continue;
            }
            let mut dmax = 0.0f64;
            for i in 0..S {
                dmax = dmax.max(dm[i * W + w]);
            }
            if rules[w].update(dmax, ymax[w])? {
                active[w] = false;
                for k in 0..M {
                    for i in 0..S {
                        saved[k][i * W + w] = g.l[k][i * W + w];
                    }
                }
            } else {
                any = true;
            }
        }
        if !any {
            break;
        }
    }
    g.l = saved;
    // Compensated update y += Σ_i L_i (Kahan), per lane.
    for k in 0..M {
        for w in 0..W {
            let mut sum = g.comp[k][w];
            for i in 0..S {
                sum += g.l[k][i * W + w];
            }
            let y = g.y[k][w];
            let new = y + sum;
            g.comp[k][w] = (y - new) + sum;
            g.y[k][w] = new;
        }
    }
    if !g.y.iter().flatten().all(|v| v.is_finite()) {
        return Err(Error::NoConvergence {
            what: "Gauss step (state overflowed or became NaN; reduce dt or rescale l)",
            tol: 0.0,
            reached: f64::NAN,
            iterations: rules.iter().map(|r| r.iterations).max().unwrap_or(0),
        });
    }
    Ok(())
}

/// Options of the dop853 lane group.
#[derive(Clone, Copy)]
pub(super) struct Dop853Opts {
    pub h0: f64,
    pub rtol: f64,
    pub atol: f64,
    pub max_steps: u64,
}

/// dop853 on the trajectories `y0s` (row-major, `rows · 6`, any number of rows)
/// through `times`, `W` at a time with refill, writing `(rows, times.len(), 6)`
/// into `out`; returns the total number of accepted steps.
pub(super) fn dop853_group(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    o: Dop853Opts,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    dispatch!(
        dop853_group_avx2,
        dop853_group_body,
        (c, y0s, t0, times, o, out, cancel)
    )
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn dop853_group_avx2(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    o: Dop853Opts,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    dop853_group_body(c, y0s, t0, times, o, out, cancel)
}

#[inline(always)]
fn dop853_group_body(
    c: &[f64; 6],
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    o: Dop853Opts,
    out: &mut [f64],
    cancel: &Cancel,
) -> Result<u64> {
    let rows = y0s.len() / M;
    let ns = times.len();
    let per = ns * M;
    // Per-lane state; a lane without a trajectory holds y = 0, k = 0, h = 0
    // (its arithmetic stays finite and its results are ignored).
    let mut y = [[0.0; W]; M];
    let mut ynew = [[0.0; W]; M];
    let mut ytmp = [[0.0; W]; M];
    let mut k = [[[0.0; W]; M]; 12];
    let mut t = [t0; W];
    let mut hcur = [0.0f64; W];
    let mut hh = [0.0f64; W];
    let mut last = [false; W];
    let mut idx = [0usize; W];
    let mut taken = [0u64; W];
    let mut traj: [Option<usize>; W] = [None; W];
    let mut next = 0usize;
    let mut total = 0u64;
    let mut since_check = 0u32;
    loop {
        // Record the samples each lane has reached; refill finished lanes.
        let mut any = false;
        for w in 0..W {
            loop {
                let Some(j) = traj[w] else {
                    if next == rows {
                        break;
                    }
                    // Load trajectory `next` (the start of `Dop853::advance`).
                    let y0: &[f64; M] = y0s[next * M..(next + 1) * M]
                        .try_into()
                        .map_err(|_| shape_err())?;
                    let f0 = vector_field4(c, y0);
                    for q in 0..M {
                        y[q][w] = y0[q];
                        k[0][q][w] = f0[q];
                    }
                    t[w] = t0;
                    hcur[w] = o.h0;
                    idx[w] = 0;
                    taken[w] = 0;
                    traj[w] = Some(next);
                    next += 1;
                    if hcur[w] == 0.0 {
                        hcur[w] = lane_starting_step(&y, &k[0], w, o);
                    }
                    continue;
                };
                if idx[w] < ns && t[w] >= times[idx[w]] {
                    let s = idx[w];
                    let dst = &mut out[j * per + s * M..j * per + (s + 1) * M];
                    for q in 0..M {
                        dst[q] = y[q][w];
                    }
                    idx[w] += 1;
                    if idx[w] < ns && hcur[w] == 0.0 {
                        hcur[w] = lane_starting_step(&y, &k[0], w, o);
                    }
                    continue;
                }
                if idx[w] == ns {
                    total += taken[w];
                    traj[w] = None;
                    for q in 0..M {
                        y[q][w] = 0.0;
                        k[0][q][w] = 0.0;
                    }
                    continue;
                }
                break;
            }
            if traj[w].is_some() {
                any = true;
                let remaining = times[idx[w]] - t[w];
                last[w] = hcur[w] >= remaining;
                hh[w] = if last[w] { remaining } else { hcur[w] };
                if hh[w] <= 1e-14 * t[w].abs().max(1.0) && !last[w] {
                    return Err(Error::NoConvergence {
                        what: "dop853 step size underflow",
                        tol: o.rtol,
                        reached: hh[w],
                        iterations: taken[w] as usize,
                    });
                }
            } else {
                hh[w] = 0.0;
                last[w] = false;
            }
        }
        if !any {
            return Ok(total);
        }
        since_check += 1;
        if since_check == CHECK_EVERY {
            since_check = 0;
            cancel.check()?;
        }
        // The 11 further stages of every lane (Dop853::advance, same order).
        for st in 1..12 {
            for q in 0..M {
                for w in 0..W {
                    let mut acc = 0.0;
                    for j in 0..st {
                        acc += DA[st][j] * k[j][q][w];
                    }
                    ytmp[q][w] = y[q][w] + hh[w] * acc;
                }
            }
            let (_, tail) = k.split_at_mut(st);
            vector_field4_lanes(c, &ytmp, &mut tail[0]);
        }
        let mut err5 = [0.0f64; W];
        let mut err3 = [0.0f64; W];
        for q in 0..M {
            for w in 0..W {
                let mut bsum = 0.0;
                let mut e5 = 0.0;
                for j in 0..12 {
                    let kj = k[j][q][w];
                    bsum += DB[j] * kj;
                    e5 += ER[j] * kj;
                }
                let e3 = bsum - BHH[0] * k[0][q][w] - BHH[1] * k[8][q][w] - BHH[2] * k[11][q][w];
                ynew[q][w] = y[q][w] + hh[w] * bsum;
                let sk = o.atol + o.rtol * y[q][w].abs().max(ynew[q][w].abs());
                err5[w] += scaled(e5, sk).powi(2);
                err3[w] += scaled(e3, sk).powi(2);
            }
        }
        let mut accepted = false;
        for w in 0..W {
            if traj[w].is_none() {
                continue;
            }
            let deno = if err5[w] + 0.01 * err3[w] > 0.0 {
                err5[w] + 0.01 * err3[w]
            } else {
                1.0
            };
            let err = hh[w].abs() * err5[w] * (1.0 / (M as f64 * deno)).sqrt();
            if !err.is_finite() {
                return Err(Error::NoConvergence {
                    what: "dop853 (state became non-finite)",
                    tol: o.rtol,
                    reached: err,
                    iterations: taken[w] as usize,
                });
            }
            let fac = (err.powf(0.125) / 0.9).clamp(1.0 / 6.0, 3.0);
            if err <= 1.0 {
                accepted = true;
                for q in 0..M {
                    y[q][w] = ynew[q][w];
                }
                t[w] = if last[w] { times[idx[w]] } else { t[w] + hh[w] };
                taken[w] += 1;
                if !last[w] {
                    hcur[w] = hh[w] / fac;
                }
            } else {
                hcur[w] = hh[w] / fac.max(1.0);
            }
            if taken[w] > o.max_steps {
                return Err(super::too_many_steps(o.max_steps));
            }
        }
        if accepted {
            // FSAL-like refresh of the first stage. A rejected lane's y is
            // unchanged, so its k1 = f(y) is recomputed to the same bits.
            let (k1, _) = k.split_at_mut(1);
            vector_field4_lanes(c, &y, &mut k1[0]);
        }
    }
}

fn shape_err() -> Error {
    Error::Shape {
        what: "l0s",
        expected: "(batch, 6)".into(),
        got: "a partial row".into(),
    }
}

/// [`starting_step`] of lane `w`.
fn lane_starting_step(y: &[[f64; W]; M], f0: &[[f64; W]; M], w: usize, o: Dop853Opts) -> f64 {
    let mut yl = [0.0; M];
    let mut fl = [0.0; M];
    for q in 0..M {
        yl[q] = y[q][w];
        fl[q] = f0[q][w];
    }
    starting_step(&yl, &fl, o.atol, o.rtol)
}
