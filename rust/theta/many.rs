//! Batches of points: split over rayon's pool for large batches (the caller
//! polling for cancellation), the vectorised genus-2 kernel (`batch.rs`) for
//! values only, and the scaling by `exp(L)` fused into it.

use super::{batch, ThetaPlan};
use crate::error::{Error, Result};
use crate::numeric::cancel::{poll_during, Cancel};
use num_complex::Complex64;
use rayon::prelude::*;

/// Work between two cancellation checks in a batch: ~1 ms (`Cancel::check`
/// costs ~50 ns, so this is free, and Ctrl-C is seen long before 0.5 s).
const CANCEL_CHECK_NS: f64 = 1e6;

/// Batches of at least this many points (values only, genus 2) use the
/// vectorised kernel; its plan-time table costs about as much as 100 points.
const BATCH_KERNEL_MIN_POINTS: usize = 64;

/// Batches of at least this many points are split over rayon's thread pool
/// (when the plan allows it): ~0.5 ms of work, well above the cost of waking
/// the pool (measured, docs/theta.md "Benchmarks").
const PARALLEL_MIN_POINTS: usize = 4096;

/// Smallest piece of a batch handed to one thread.
const PARALLEL_CHUNK: usize = 1024;

impl ThetaPlan {
    /// Evaluates a batch: `z` holds `npts` points of `g` entries (row-major);
    /// the outputs hold `npts` blocks of 4^g, 4^g·g and 4^g·g² entries
    /// (gradient/Hessian may be empty to skip them); `log_scale` has `npts` entries.
    /// With [`ThetaPlan::with_parallel`] (the default) large batches are split
    /// over rayon's thread pool.
    pub fn eval_batch(
        &self,
        z: &[Complex64],
        values: &mut [Complex64],
        gradient: &mut [Complex64],
        hessian: &mut [Complex64],
        log_scale: &mut [f64],
    ) -> Result<()> {
        self.eval_batch_cancel(z, values, gradient, hessian, log_scale, &Cancel::never())
    }

    /// [`ThetaPlan::eval_batch`] that checks `cancel` about every millisecond of
    /// work and stops with [`Error::Interrupted`] (outputs then partly written).
    pub fn eval_batch_cancel(
        &self,
        z: &[Complex64],
        values: &mut [Complex64],
        gradient: &mut [Complex64],
        hessian: &mut [Complex64],
        log_scale: &mut [f64],
        cancel: &Cancel,
    ) -> Result<()> {
        let g = self.g;
        let n = 1usize << (2 * g);
        let npts = log_scale.len();
        let (gs, hs) = (n * g, n * g * g);
        let shapes_ok = z.len() == npts * g
            && values.len() == npts * n
            && (gradient.is_empty() || gradient.len() == npts * gs)
            && (hessian.is_empty() || hessian.len() == npts * hs);
        let Some(chunk) = self.parallel_chunk(npts).filter(|_| shapes_ok) else {
            return self.eval_batch_serial(z, values, gradient, hessian, log_scale, cancel);
        };
        let gs = if gradient.is_empty() { 0 } else { gs };
        let hs = if hessian.is_empty() { 0 } else { hs };
        let mut gchunks: Vec<&mut [Complex64]> = if gs == 0 {
            (0..npts.div_ceil(chunk)).map(|_| &mut [][..]).collect()
        } else {
            gradient.chunks_mut(chunk * gs).collect()
        };
        let mut hchunks: Vec<&mut [Complex64]> = if hs == 0 {
            (0..npts.div_ceil(chunk)).map(|_| &mut [][..]).collect()
        } else {
            hessian.chunks_mut(chunk * hs).collect()
        };
        poll_during(cancel, || {
            z.par_chunks(chunk * g)
                .zip(values.par_chunks_mut(chunk * n))
                .zip(gchunks.par_iter_mut())
                .zip(hchunks.par_iter_mut())
                .zip(log_scale.par_chunks_mut(chunk))
                .try_for_each(|((((zc, vc), gc), hc), lc)| {
                    self.eval_batch_serial(zc, vc, gc, hc, lc, cancel)
                })
        })
    }

    /// Points between two cancellation checks (about [`CANCEL_CHECK_NS`] of work
    /// by the cost model, whole kernel chunks).
    fn points_per_check(&self) -> usize {
        let per = CANCEL_CHECK_NS / (self.info().seconds_per_point * 1e9).max(1.0);
        ((per as usize).max(1)).div_ceil(batch::LANES) * batch::LANES
    }

    /// Chunk size for splitting a batch of `npts` points over the thread pool,
    /// `None` to stay on the calling thread.
    fn parallel_chunk(&self, npts: usize) -> Option<usize> {
        let threads = rayon::current_num_threads();
        if !self.parallel || threads < 2 || npts < PARALLEL_MIN_POINTS {
            return None;
        }
        // Many chunks per thread (≥ PARALLEL_CHUNK points, ~0.2 ms each): on a
        // shared machine a thread may lose its core for a while, and work stealing
        // can only rebalance if there is work left to steal. Whole kernel chunks.
        let per = npts.div_ceil(16 * threads).max(PARALLEL_CHUNK);
        Some(per.div_ceil(batch::LANES) * batch::LANES)
    }

    fn eval_batch_serial(
        &self,
        z: &[Complex64],
        values: &mut [Complex64],
        gradient: &mut [Complex64],
        hessian: &mut [Complex64],
        log_scale: &mut [f64],
        cancel: &Cancel,
    ) -> Result<()> {
        let g = self.g;
        let n = 1usize << (2 * g);
        let npts = log_scale.len();
        if z.len() != npts * g || values.len() != npts * n {
            return Err(Error::Shape {
                what: "theta batch",
                expected: format!("{npts} points of {g} entries, {n} values each"),
                got: format!("{} z entries, {} values", z.len(), values.len()),
            });
        }
        let mut ws = self.workspace();
        if gradient.is_empty() && hessian.is_empty() && npts >= BATCH_KERNEL_MIN_POINTS {
            if let Some(b2) = self.batch2.get_or_init(|| batch::Batch2::build(self)) {
                return self
                    .eval_batch_g2(b2, z, values, log_scale, false, cancel)
                    .map(|_| ());
            }
        }
        let gstride = if gradient.is_empty() { 0 } else { n * g };
        let hstride = if hessian.is_empty() { 0 } else { n * g * g };
        if gradient.len() != npts * gstride || hessian.len() != npts * hstride {
            return Err(Error::Shape {
                what: "theta batch derivatives",
                expected: format!(
                    "{} gradient, {} hessian entries",
                    npts * n * g,
                    npts * n * g * g
                ),
                got: format!("{}, {}", gradient.len(), hessian.len()),
            });
        }
        let every = self.points_per_check();
        for i in 0..npts {
            if i % every == 0 {
                cancel.check()?;
            }
            log_scale[i] = self.eval_into_cancel(
                &z[i * g..(i + 1) * g],
                &mut ws,
                &mut values[i * n..(i + 1) * n],
                &mut gradient[i * gstride..(i + 1) * gstride],
                &mut hessian[i * hstride..(i + 1) * hstride],
                Some(cancel),
            )?;
        }
        Ok(())
    }

    /// Values only, genus 2: chunks of [`batch::LANES`] points through the
    /// vectorised kernel, then the usual combination per point.
    fn eval_batch_g2(
        &self,
        b2: &batch::Batch2,
        z: &[Complex64],
        values: &mut [Complex64],
        log_scale: &mut [f64],
        scaled: bool,
        cancel: &Cancel,
    ) -> Result<bool> {
        const L: usize = batch::LANES;
        let mut finite = true;
        let npts = log_scale.len();
        let every = self.points_per_check();
        let mut sc = b2.scratch();
        let mut inp = batch::ChunkIn::default();
        let mut i0 = 0;
        while i0 < npts {
            if i0 % every == 0 {
                cancel.check()?;
            }
            let m = (npts - i0).min(L);
            if m < L {
                inp = batch::ChunkIn::default();
            }
            for p in 0..m {
                let k = i0 + p;
                let red = self.reduce2::<false>([z[2 * k], z[2 * k + 1]])?;
                inp.set(p, &red);
                log_scale[k] = red.log_scale;
            }
            b2.eval_chunk(self, &inp, scaled, batch::ALL, &mut sc);
            for p in 0..m {
                let k = i0 + p;
                let out = &mut values[16 * k..16 * k + 16];
                for (idx, v) in out.iter_mut().enumerate() {
                    *v = Complex64::new(sc.out_re[idx][p], sc.out_im[idx][p]);
                }
                // |Ω| ≤ number of terms ≤ MAX_TERMS = 2e8, so exp(L)|Ω| < f64::MAX for L ≤ 690
                if scaled && inp.logs[p] > 690.0 {
                    finite &= out.iter().all(|v| v.re.is_finite() && v.im.is_finite());
                }
            }
            i0 += m;
        }
        Ok(finite)
    }

    /// Values θ themselves (not normalised) for a batch, as [`ThetaPlan::eval_batch`]
    /// without derivatives followed by [`apply_scale`], but with the scaling fused
    /// into the genus-2 kernel. Returns `Ok(false)` if some value overflows.
    pub fn eval_batch_scaled(
        &self,
        z: &[Complex64],
        values: &mut [Complex64],
        log_scale: &mut [f64],
    ) -> Result<bool> {
        self.eval_batch_scaled_cancel(z, values, log_scale, &Cancel::never())
    }

    /// [`ThetaPlan::eval_batch_scaled`] that checks `cancel` about every
    /// millisecond of work and stops with [`Error::Interrupted`].
    pub fn eval_batch_scaled_cancel(
        &self,
        z: &[Complex64],
        values: &mut [Complex64],
        log_scale: &mut [f64],
        cancel: &Cancel,
    ) -> Result<bool> {
        let (g, npts) = (self.g, log_scale.len());
        let n = 1usize << (2 * g);
        let shapes_ok = z.len() == npts * g && values.len() == npts * n;
        let Some(chunk) = self.parallel_chunk(npts).filter(|_| shapes_ok) else {
            return self.eval_batch_scaled_serial(z, values, log_scale, cancel);
        };
        poll_during(cancel, || {
            z.par_chunks(chunk * g)
                .zip(values.par_chunks_mut(chunk * n))
                .zip(log_scale.par_chunks_mut(chunk))
                .map(|((zc, vc), lc)| self.eval_batch_scaled_serial(zc, vc, lc, cancel))
                .try_reduce(|| true, |a, b| Ok(a && b))
        })
    }

    fn eval_batch_scaled_serial(
        &self,
        z: &[Complex64],
        values: &mut [Complex64],
        log_scale: &mut [f64],
        cancel: &Cancel,
    ) -> Result<bool> {
        let npts = log_scale.len();
        if z.len() == 2 * npts && values.len() == 16 * npts && npts >= BATCH_KERNEL_MIN_POINTS {
            if let Some(b2) = self.batch2.get_or_init(|| batch::Batch2::build(self)) {
                return self.eval_batch_g2(b2, z, values, log_scale, true, cancel);
            }
        }
        self.eval_batch_serial(z, values, &mut [], &mut [], log_scale, cancel)?;
        Ok(apply_scale(values, &mut [], &mut [], log_scale))
    }
}

impl ThetaPlan {
    /// The derivative widths `(gd, hd)` of a batch at the plan's order
    /// (gradient `(n, 4^g, gd)`, Hessian `(n, 4^g, gd, hd)`), after checking
    /// that the outputs of `npts` points fit the address space (checked before
    /// anything is allocated: a batch too large to address is refused, never
    /// an abort or a panic).
    pub fn batch_widths(&self, npts: usize) -> Result<(usize, usize)> {
        let g = self.g;
        let n = 1usize << (2 * g);
        let (gd, hd) = match self.order {
            0 => (0, 0),
            1 => (g, 0),
            _ => (g, g),
        };
        let per_point = n * (1 + gd + gd * hd); // values, gradient, Hessian entries
        let entries = npts.checked_mul(per_point).filter(|&e| {
            e.checked_mul(std::mem::size_of::<Complex64>())
                .is_some_and(|b| b <= isize::MAX as usize)
        });
        if entries.is_none() {
            return Err(Error::InvalidArgument {
                what: "z",
                reason: format!(
                    "{npts} points of genus {g} need {npts} x {per_point} complex outputs: \
                     more than the address space"
                ),
            });
        }
        Ok((gd, hd))
    }

    /// A batch at the plan's order: normalised values and derivatives, or
    /// (`scaled`) θ itself, with the scaling fused into the genus-2 kernel for
    /// values only. Returns `false` if, scaled, some value overflowed.
    #[allow(clippy::too_many_arguments)]
    pub fn eval_batch_jet(
        &self,
        z: &[Complex64],
        values: &mut [Complex64],
        gradient: &mut [Complex64],
        hessian: &mut [Complex64],
        log_scale: &mut [f64],
        scaled: bool,
        cancel: &Cancel,
    ) -> Result<bool> {
        if scaled && self.order == 0 {
            return self.eval_batch_scaled_cancel(z, values, log_scale, cancel);
        }
        self.eval_batch_cancel(z, values, gradient, hessian, log_scale, cancel)?;
        Ok(!scaled || apply_scale(values, gradient, hessian, log_scale))
    }
}

/// Multiplies batch outputs of [`ThetaPlan::eval_batch`] by `exp(L)` in place, giving
/// θ itself. Returns `false` (leaving the outputs partly scaled) if some value
/// is not a finite double, i.e. θ overflows.
pub fn apply_scale(
    values: &mut [Complex64],
    gradient: &mut [Complex64],
    hessian: &mut [Complex64],
    log_scale: &[f64],
) -> bool {
    let npts = log_scale.len();
    if npts == 0 {
        return true;
    }
    let (nv, ng, nh) = (
        values.len() / npts,
        gradient.len() / npts,
        hessian.len() / npts,
    );
    let mut ok = true;
    for (i, &l) in log_scale.iter().enumerate() {
        let f = l.exp();
        for v in values[i * nv..(i + 1) * nv]
            .iter_mut()
            .chain(gradient[i * ng..(i + 1) * ng].iter_mut())
            .chain(hessian[i * nh..(i + 1) * nh].iter_mut())
        {
            *v *= f;
            ok &= v.re.is_finite() && v.im.is_finite();
        }
    }
    ok
}
