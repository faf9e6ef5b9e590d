//! The dop853 lane group of the so(4) batch kernels ([`super::batch`]): each
//! lane keeps its own time, step size, next sample and step count; a rejected
//! step is masked by the per-lane control, and a lane whose trajectory has
//! reached its last sample is refilled with the next trajectory of the group.
//! Every lane performs the floating-point operations of the single-trajectory
//! stepper in the same order, so the results are those of `integrate`, bit for
//! bit (the tests of [`super::batch`]).

// Index loops mirror the subscripts of the formulas (i, j stages; k components; w lanes).
#![allow(clippy::needless_range_loop)]

use super::batch::{dispatch, M, W};
use super::dop853::{A as DA, B as DB, BHH, ER};
use super::explicit::{scaled, starting_step, too_many_steps};
use crate::error::{Error, Result};
use crate::numeric::cancel::{Cancel, CHECK_EVERY};
use crate::numeric::tol::min_step;
use crate::so4::{vector_field4, vector_field4_lanes};

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

/// dop853 on the lane group (see [`dop853_group`]): record the samples the
/// lanes have reached, refill finished lanes and choose each lane's step, the
/// 11 further stages, the error estimate, the step control, the first stage of
/// the next step. Every step is `#[inline(always)]`: the body is instantiated
/// inside the AVX2 `#[target_feature]` copy, and its steps must be compiled
/// with the same features.
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
    let run = Dop853Run {
        c,
        y0s,
        t0,
        times,
        o,
        rows: y0s.len() / M,
        ns: times.len(),
        per: times.len() * M,
    };
    // Per-lane state; a lane without a trajectory holds y = 0, k = 0, h = 0
    // (its arithmetic stays finite and its results are ignored). The state and
    // the stages stay out of the lane-state struct, as separate arrays, as in
    // the former single body.
    let mut y = [[0.0; W]; M];
    let mut k = [[[0.0; W]; M]; 12];
    let mut lanes = Dop853Lanes::new(t0);
    let mut since_check = 0u32;
    loop {
        if !lanes.record_and_refill(&mut y, &mut k, &run, out, cancel)? {
            return Ok(lanes.total);
        }
        since_check += 1;
        if since_check == CHECK_EVERY {
            since_check = 0;
            cancel.check()?;
        }
        lanes.stages(&y, &mut k, c);
        let (ynew, err5, err3) = lanes.error_estimate(&y, &k, o);
        let accepted = lanes.control(&mut y, &ynew, &err5, &err3, &run)?;
        if accepted {
            // FSAL-like refresh of the first stage. A rejected lane's y is
            // unchanged, so its k1 = f(y) is recomputed to the same bits.
            let (k1, _) = k.split_at_mut(1);
            vector_field4_lanes(c, &y, &mut k1[0]);
        }
    }
}

/// What a run of the dop853 lane group does not change.
struct Dop853Run<'a> {
    c: &'a [f64; 6],
    y0s: &'a [f64],
    t0: f64,
    times: &'a [f64],
    o: Dop853Opts,
    rows: usize,
    ns: usize,
    /// Output values per trajectory.
    per: usize,
}

/// The dop853 stages `k[i][q][w]` of the `W` lanes.
type Stages = [[[f64; W]; M]; 12];

/// The per-lane scalars of the dop853 lane group (the state and the stages
/// are arrays of their own: [`dop853_group_body`]).
struct Dop853Lanes {
    t: [f64; W],
    /// The proposed step of each lane.
    hcur: [f64; W],
    /// The step being taken (cut to the next sample).
    hh: [f64; W],
    /// The step ends on the next sample.
    last: [bool; W],
    /// The next sample of each lane.
    idx: [usize; W],
    /// Accepted steps of each lane's trajectory.
    taken: [u64; W],
    /// Each lane's trajectory (`None`: idle).
    traj: [Option<usize>; W],
    /// The next trajectory to load.
    next: usize,
    /// Accepted steps of the trajectories finished so far.
    total: u64,
}

impl Dop853Lanes {
    #[inline(always)]
    fn new(t0: f64) -> Self {
        Dop853Lanes {
            t: [t0; W],
            hcur: [0.0f64; W],
            hh: [0.0f64; W],
            last: [false; W],
            idx: [0usize; W],
            taken: [0u64; W],
            traj: [None; W],
            next: 0usize,
            total: 0u64,
        }
    }

    /// Record the samples each lane has reached; refill finished lanes; the
    /// step each lane takes next. Returns whether any lane has a trajectory.
    #[inline(always)]
    fn record_and_refill(
        &mut self,
        y: &mut [[f64; W]; M],
        k: &mut Stages,
        run: &Dop853Run,
        out: &mut [f64],
        cancel: &Cancel,
    ) -> Result<bool> {
        let (times, ns, per, o) = (run.times, run.ns, run.per, run.o);
        let mut any = false;
        for w in 0..W {
            loop {
                let Some(j) = self.traj[w] else {
                    if self.next == run.rows {
                        break;
                    }
                    self.load(y, k, w, run)?;
                    continue;
                };
                if self.idx[w] < ns && self.t[w] >= times[self.idx[w]] {
                    let s = self.idx[w];
                    let dst = &mut out[j * per + s * M..j * per + (s + 1) * M];
                    for q in 0..M {
                        dst[q] = y[q][w];
                    }
                    self.idx[w] += 1;
                    cancel.advance(1);
                    if self.idx[w] < ns && self.hcur[w] == 0.0 {
                        self.hcur[w] = lane_starting_step(y, &k[0], w, o);
                    }
                    continue;
                }
                if self.idx[w] == ns {
                    self.total += self.taken[w];
                    self.traj[w] = None;
                    for q in 0..M {
                        y[q][w] = 0.0;
                        k[0][q][w] = 0.0;
                    }
                    continue;
                }
                break;
            }
            if self.traj[w].is_some() {
                any = true;
                self.choose_step(w, run)?;
            } else {
                self.hh[w] = 0.0;
                self.last[w] = false;
            }
        }
        Ok(any)
    }

    /// Load trajectory `next` into lane `w` (the start of `Dop853::advance`).
    #[inline(always)]
    fn load(
        &mut self,
        y: &mut [[f64; W]; M],
        k: &mut Stages,
        w: usize,
        run: &Dop853Run,
    ) -> Result<()> {
        let (next, o) = (self.next, run.o);
        let y0: &[f64; M] = run.y0s[next * M..(next + 1) * M]
            .try_into()
            .map_err(|_| shape_err())?;
        let f0 = vector_field4(run.c, y0);
        for q in 0..M {
            y[q][w] = y0[q];
            k[0][q][w] = f0[q];
        }
        self.t[w] = run.t0;
        self.hcur[w] = o.h0;
        self.idx[w] = 0;
        self.taken[w] = 0;
        self.traj[w] = Some(next);
        self.next += 1;
        if self.hcur[w] == 0.0 {
            self.hcur[w] = lane_starting_step(y, &k[0], w, o);
        }
        Ok(())
    }

    /// The step lane `w` takes: its proposed step, cut to its next sample;
    /// errors on a step below the time's resolution.
    #[inline(always)]
    fn choose_step(&mut self, w: usize, run: &Dop853Run) -> Result<()> {
        let remaining = run.times[self.idx[w]] - self.t[w];
        self.last[w] = self.hcur[w] >= remaining;
        self.hh[w] = if self.last[w] {
            remaining
        } else {
            self.hcur[w]
        };
        if self.hh[w] <= min_step(self.t[w]) && !self.last[w] {
            return Err(Error::NoConvergence {
                what: "dop853 step size underflow",
                tol: run.o.rtol,
                reached: self.hh[w],
                iterations: self.taken[w] as usize,
            });
        }
        Ok(())
    }

    /// The 11 further stages of every lane (Dop853::advance, same order).
    #[inline(always)]
    fn stages(&self, y: &[[f64; W]; M], k: &mut Stages, c: &[f64; 6]) {
        let hh = &self.hh;
        let mut ytmp = [[0.0; W]; M];
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
    }

    /// The 8th-order solution `ynew` and the squared scaled norms of the 5th-
    /// and 3rd-order error estimates of every lane.
    #[inline(always)]
    fn error_estimate(
        &self,
        y: &[[f64; W]; M],
        k: &Stages,
        o: Dop853Opts,
    ) -> ([[f64; W]; M], [f64; W], [f64; W]) {
        let hh = &self.hh;
        let mut ynew = [[0.0; W]; M];
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
        (ynew, err5, err3)
    }

    /// The step control of every lane: accept (state, time, step count, next
    /// step) or reject (a smaller step); returns whether any lane accepted.
    /// Errors on a non-finite error estimate or a lane out of steps.
    #[inline(always)]
    fn control(
        &mut self,
        y: &mut [[f64; W]; M],
        ynew: &[[f64; W]; M],
        err5: &[f64; W],
        err3: &[f64; W],
        run: &Dop853Run,
    ) -> Result<bool> {
        let (times, o) = (run.times, run.o);
        let mut accepted = false;
        for w in 0..W {
            if self.traj[w].is_none() {
                continue;
            }
            let deno = if err5[w] + 0.01 * err3[w] > 0.0 {
                err5[w] + 0.01 * err3[w]
            } else {
                1.0
            };
            let err = self.hh[w].abs() * err5[w] * (1.0 / (M as f64 * deno)).sqrt();
            if !err.is_finite() {
                return Err(Error::NoConvergence {
                    what: "dop853 (state became non-finite)",
                    tol: o.rtol,
                    reached: err,
                    iterations: self.taken[w] as usize,
                });
            }
            let fac = (err.powf(0.125) / 0.9).clamp(1.0 / 6.0, 3.0);
            if err <= 1.0 {
                accepted = true;
                for q in 0..M {
                    y[q][w] = ynew[q][w];
                }
                self.t[w] = if self.last[w] {
                    times[self.idx[w]]
                } else {
                    self.t[w] + self.hh[w]
                };
                self.taken[w] += 1;
                if !self.last[w] {
                    self.hcur[w] = self.hh[w] / fac;
                }
            } else {
                self.hcur[w] = self.hh[w] / fac.max(1.0);
            }
            if self.taken[w] > o.max_steps {
                return Err(too_many_steps(o.max_steps));
            }
        }
        Ok(accepted)
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
