//! The entry points: one trajectory ([`integrate`] and its variants) and
//! batches ([`integrate_many`]) on the trajectory-lane kernels, split over
//! rayon's pool with the calling thread polling for cancellation.

use rayon::prelude::*;

use super::dopri5::Dopri5;
use super::explicit::Explicit;
use super::gauss::{run_gauss, GaussDyn, GaussFixed};
use super::{batch, batch_dop853, dop853, gauss_tables, taylor};
use super::{check_budget, check_sample_times, Method, Options, Trajectory, VectorField, LANES};
use crate::error::{check_finite, Error, Result};
use crate::numeric::alloc::{check_size, try_collect, try_vec};
use crate::numeric::cancel::{poll_during, Cancel};

/// A zeroed output buffer of `rows` trajectories of `per` doubles, through the
/// checked allocation of `numeric::alloc`: a size over the budget or one the
/// machine cannot hold is an error naming it, not an abort.
pub(super) fn alloc_output(rows: usize, per: usize) -> Result<Vec<f64>> {
    check_size(
        "samples",
        rows,
        per.saturating_mul(std::mem::size_of::<f64>()),
    )?;
    try_vec("samples", rows.saturating_mul(per), 0.0)
}

/// Integrates `ẏ = f(y)` from `y0` at time `t0`, recording the state at each of
/// `times` (sorted, `≥ t0`); see the module docs for the methods and sampling.
///
/// Errors: `Shape` if `y0` has the wrong length; `NonFinite`; `InvalidArgument`
/// for bad options or unsorted times or too many steps; `NoConvergence` if a
/// Gauss step cannot be solved (step too large) or `dopri5` fails.
pub fn integrate<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
) -> Result<Trajectory> {
    integrate_with(f, y0, t0, times, opts, &Cancel::never())
}

/// [`integrate`], stopping with `Error::Interrupted` once `cancel` is cancelled.
pub fn integrate_with<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    cancel: &Cancel,
) -> Result<Trajectory> {
    let (tr, res) = integrate_partial(f, y0, t0, times, opts, cancel)?;
    res.map(|()| tr)
}

/// [`integrate_with`] that keeps what was computed: the outer `Err` is a refused
/// call (bad arguments, over budget: nothing was computed); otherwise the
/// trajectory holds the samples reached (all of them when the inner result is
/// `Ok`, those before the failure or interruption when it is `Err`).
pub fn integrate_partial<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    cancel: &Cancel,
) -> Result<(Trajectory, Result<()>)> {
    let m = f.dim();
    if y0.len() != m {
        return Err(Error::Shape {
            what: "l0",
            expected: format!("({m},)"),
            got: format!("({},)", y0.len()),
        });
    }
    check_finite("l0", y0)?;
    opts.validate()?;
    check_sample_times(t0, times)?;
    check_budget(opts.method, t0, times, opts.dt, opts.max_steps)?;
    taylor_coefficients(f, opts.method)?;
    let mut y = alloc_output(times.len(), m)?;
    y.clear();
    let mut out = Trajectory {
        t: Vec::new(),
        y,
        steps: 0,
        evals: 0,
    };
    let res = integrate_into(f, y0, t0, times, opts, &mut out, cancel);
    let reached = &times[..out.y.len() / m.max(1)];
    out.t = try_collect("samples", reached.len(), reached.iter().copied())?;
    Ok((out, res))
}

/// The loop of [`integrate`] (validated inputs): appends the samples to
/// `out.y` and adds the steps and evaluations to its counts.
fn integrate_into<F: VectorField>(
    f: &F,
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    out: &mut Trajectory,
    cancel: &Cancel,
) -> Result<()> {
    let m = f.dim();
    if opts.method == Method::Taylor {
        let c = taylor_coefficients(f, opts.method)?.ok_or_else(taylor_so4_only)?;
        return taylor_into(c, y0, t0, times, opts, out, cancel);
    }
    let mut y = y0.to_vec();
    if opts.method.stages().is_some() {
        gauss_into(f, &mut y, t0, times, opts, out, cancel)
    } else if opts.method == Method::Dop853 {
        let d = dop853::Dop853::new(m, opts.dt, opts.rtol, opts.atol);
        explicit_into(d, f, &mut y, t0, times, opts.max_steps, out, cancel)
    } else {
        let d = Dopri5::new(m, opts);
        explicit_into(d, f, &mut y, t0, times, opts.max_steps, out, cancel)
    }
}

/// Taylor's method on one trajectory: in a lane group of its own (the other
/// lanes idle), so that it gives the bits of [`integrate_many`].
fn taylor_into(
    c: &[f64; 6],
    y0: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    out: &mut Trajectory,
    cancel: &Cancel,
) -> Result<()> {
    let m = y0.len();
    let ys = &mut out.y;
    let start = ys.len();
    let n = times.len() * m;
    ys.try_reserve_exact(n)
        .map_err(|_| Error::InvalidArgument {
            what: "output size",
            reason: "cannot allocate the samples of one trajectory".into(),
        })?;
    ys.resize(start + n, 0.0);
    let mut progress = taylor::Progress::default();
    let res = taylor::taylor_group(
        c,
        y0,
        t0,
        times,
        taylor_opts(opts),
        &mut ys[start..],
        &mut progress,
        cancel,
    );
    ys.truncate(start + progress.samples0 * m);
    out.steps += progress.steps;
    out.evals += progress.steps * taylor::order(opts.rtol) as u64;
    res
}

/// A Gauss method on one trajectory: the fixed-size stepper for so(4)
/// (`dim = 6`), else the one for any dimension.
fn gauss_into<F: VectorField>(
    f: &F,
    y: &mut [f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    out: &mut Trajectory,
    cancel: &Cancel,
) -> Result<()> {
    use gauss_tables::*;
    let dt = opts.dt;
    match (opts.method, f.dim()) {
        (Method::Gauss4, 6) => {
            let g = GaussFixed::<2, 6>::new(&B2, &MU2, &E2);
            run_gauss(g, f, y, t0, times, dt, out, cancel)
        }
        (Method::Gauss6, 6) => {
            let g = GaussFixed::<3, 6>::new(&B3, &MU3, &E3);
            run_gauss(g, f, y, t0, times, dt, out, cancel)
        }
        (Method::Gauss16, 6) => {
            let g = GaussFixed::<8, 6>::new(&B8, &MU8, &E8);
            run_gauss(g, f, y, t0, times, dt, out, cancel)
        }
        (method, m) => {
            let g = GaussDyn::new(method, m).ok_or_else(|| Error::InvalidArgument {
                what: "method",
                reason: "not a Gauss method".into(),
            })?;
            run_gauss(g, f, y, t0, times, dt, out, cancel)
        }
    }
}

/// An explicit method on one trajectory, from sample time to sample time.
#[allow(clippy::too_many_arguments)]
fn explicit_into<E: Explicit, F: VectorField>(
    mut d: E,
    f: &F,
    y: &mut [f64],
    t0: f64,
    times: &[f64],
    max_steps: u64,
    out: &mut Trajectory,
    cancel: &Cancel,
) -> Result<()> {
    let mut t = t0;
    let res = (|| {
        for &tk in times {
            out.steps += d.advance(f, y, &mut t, tk, max_steps - out.steps, cancel)?;
            out.y.extend_from_slice(y);
            // One sample done; and a check: the step loop checks only every
            // CHECK_EVERY attempts within one sample interval, so a run sampled
            // more often than that would otherwise never see Ctrl-C.
            cancel.advance(1);
            cancel.check()?;
        }
        Ok(())
    })();
    out.evals += d.evals();
    res
}

/// Trajectories per rayon task of the dop853 and Taylor batch kernels: 8 lane
/// groups, so a lane freed by a finished trajectory is refilled from the same task.
const DOP853_TASK: usize = 8 * LANES;

/// Most trajectories per rayon task of the Taylor batch kernel: 32 lane groups.
/// A lane idles from its task's last trajectory on until the slowest lane ends
/// (trajectories to t = 100 take 264-924 steps on the 1000-state benchmark
/// batch): lane utilisation 94.6 % with tasks of 32 trajectories, 98.6 % with
/// 128. Smaller tasks only to give every thread four (see [`taylor_task`]).
const TAYLOR_TASK: usize = 32 * LANES;

/// The Taylor task size for `rows` trajectories: [`TAYLOR_TASK`], or less (down
/// to [`DOP853_TASK`]) so that a parallel run has four tasks per thread. The
/// lanes are independent, so the split does not change any result.
fn taylor_task(rows: usize, parallel: bool) -> usize {
    if !parallel {
        return TAYLOR_TASK;
    }
    let per = rows / (4 * rayon::current_num_threads().max(1));
    (per / LANES * LANES).clamp(DOP853_TASK, TAYLOR_TASK)
}

fn taylor_so4_only() -> Error {
    Error::InvalidArgument {
        what: "method",
        reason: "taylor is implemented for the so(4) top only (n = 4)".into(),
    }
}

/// The so(4) coefficients of `f` when `method` is Taylor's (which needs them),
/// `None` for other methods; an error for Taylor's method on another field.
fn taylor_coefficients<F: VectorField>(f: &F, method: Method) -> Result<Option<&[f64; 6]>> {
    if method != Method::Taylor {
        return Ok(None);
    }
    f.so4_coefficients().map(Some).ok_or_else(taylor_so4_only)
}

fn taylor_opts(opts: &Options) -> taylor::TaylorOpts {
    taylor::TaylorOpts {
        tol: opts.rtol,
        h_max: opts.dt,
        max_steps: opts.max_steps,
    }
}

/// Integrates a batch of initial states `y0s` (row-major, `(batch, dim)`) with the
/// same options and sample times; returns the states row-major
/// `(batch, samples, dim)` and the total number of steps. With `parallel`, the
/// batch is split over rayon's thread pool.
///
/// For the so(4) top with gauss16 or dop853 the batch runs on the trajectory-lane
/// kernels (see the module docs); the results are those of [`integrate`] state by
/// state, bit for bit. The budget and the output size are checked before any work.
pub fn integrate_many<F: VectorField>(
    f: &F,
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    parallel: bool,
) -> Result<(Vec<f64>, u64)> {
    integrate_many_with(f, y0s, t0, times, opts, parallel, &Cancel::never())
}

/// [`integrate_many`], stopping with `Error::Interrupted` once `cancel` is cancelled.
pub fn integrate_many_with<F: VectorField>(
    f: &F,
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    parallel: bool,
    cancel: &Cancel,
) -> Result<(Vec<f64>, u64)> {
    let m = f.dim();
    if m == 0 || y0s.len() % m != 0 {
        return Err(Error::Shape {
            what: "l0s",
            expected: format!("(batch, {m})"),
            got: format!("{} entries", y0s.len()),
        });
    }
    check_finite("l0s", y0s)?;
    opts.validate()?;
    check_sample_times(t0, times)?;
    check_budget(opts.method, t0, times, opts.dt, opts.max_steps)?;
    taylor_coefficients(f, opts.method)?;
    let rows = y0s.len() / m;
    let per = times.len() * m;
    let mut out = alloc_output(rows, per)?;
    if out.is_empty() {
        return Ok((out, 0));
    }
    let lanes = f.so4_coefficients().filter(|_| {
        matches!(
            opts.method,
            Method::Gauss16 | Method::Dop853 | Method::Taylor
        )
    });
    // One task's worth of work runs on the calling thread: no pool, no poller thread.
    let task = match (lanes, opts.method) {
        (Some(_), Method::Gauss16) => LANES,
        (Some(_), Method::Taylor) => taylor_task(rows, parallel),
        (Some(_), _) => DOP853_TASK,
        (None, _) => 1,
    };
    let parallel = parallel && rows > task;
    let mut run = || -> Result<u64> {
        let steps = match lanes {
            Some(c) => lane_groups(
                (c, m),
                y0s,
                t0,
                times,
                opts,
                task,
                &mut out,
                parallel,
                cancel,
            )?,
            None => {
                let one = |(y0, chunk): (&[f64], &mut [f64])| -> Result<u64> {
                    let ys = crate::numeric::alloc::try_with_capacity("samples", per)?;
                    let mut tr = Trajectory {
                        t: Vec::new(),
                        y: ys,
                        steps: 0,
                        evals: 0,
                    };
                    integrate_into(f, y0, t0, times, opts, &mut tr, cancel)?;
                    chunk.copy_from_slice(&tr.y);
                    Ok(tr.steps)
                };
                map_chunks(y0s, &mut out, m, per, parallel, one)?
            }
        };
        Ok(steps.iter().sum())
    };
    let steps = if parallel {
        poll_during(cancel, run)
    } else {
        run()
    }?;
    Ok((out, steps))
}

/// The so(4) batch on the trajectory-lane kernels (gauss16, Taylor, dop853),
/// `task` trajectories (of dimension `m`) per work unit; the steps of each unit.
#[allow(clippy::too_many_arguments)]
fn lane_groups(
    (c, m): (&[f64; 6], usize),
    y0s: &[f64],
    t0: f64,
    times: &[f64],
    opts: &Options,
    task: usize,
    out: &mut [f64],
    parallel: bool,
    cancel: &Cancel,
) -> Result<Vec<u64>> {
    let per = times.len() * m;
    let (gy, go) = (task * m, task * per);
    match opts.method {
        Method::Gauss16 => {
            let group = |(y0, o): (&[f64], &mut [f64])| -> Result<u64> {
                let n = batch::gauss16_group(c, y0, t0, times, opts.dt, o, cancel)?;
                Ok(n * (y0.len() / m) as u64)
            };
            map_chunks(y0s, out, gy, go, parallel, group)
        }
        Method::Taylor => {
            let to = taylor_opts(opts);
            let group = |(y0, o): (&[f64], &mut [f64])| -> Result<u64> {
                let mut progress = taylor::Progress::default();
                taylor::taylor_group(c, y0, t0, times, to, o, &mut progress, cancel)?;
                Ok(progress.steps)
            };
            map_chunks(y0s, out, gy, go, parallel, group)
        }
        _ => {
            let o8 = batch_dop853::Dop853Opts {
                h0: opts.dt,
                rtol: opts.rtol,
                atol: opts.atol,
                max_steps: opts.max_steps,
            };
            let group = |(y0, o): (&[f64], &mut [f64])| {
                batch_dop853::dop853_group(c, y0, t0, times, o8, o, cancel)
            };
            map_chunks(y0s, out, gy, go, parallel, group)
        }
    }
}

/// `work` on the pairs of `gy`-chunks of `y0s` and `go`-chunks of `out`, over
/// rayon's pool or in order on the calling thread.
fn map_chunks<W>(
    y0s: &[f64],
    out: &mut [f64],
    gy: usize,
    go: usize,
    parallel: bool,
    work: W,
) -> Result<Vec<u64>>
where
    W: Fn((&[f64], &mut [f64])) -> Result<u64> + Sync + Send,
{
    if parallel {
        y0s.par_chunks(gy)
            .zip(out.par_chunks_mut(go))
            .map(work)
            .collect::<Result<_>>()
    } else {
        y0s.chunks(gy)
            .zip(out.chunks_mut(go))
            .map(work)
            .collect::<Result<_>>()
    }
}
