//! Genus 2, values only, for selected characteristics at blocks of
//! [`BLOCK`] points, handed to a sink while hot in cache: the route of the
//! Theorem's `l(t)` (`crate::solution`).

use super::{batch, ThetaPlan};
use crate::error::{Error, Result};
use num_complex::Complex64;

/// Points per block of [`ThetaPlan::eval_selected_g2`].
pub const BLOCK: usize = batch::LANES;

/// Normalised values of selected characteristics at one block of genus-2
/// points, structure of arrays: `Ω[chars[m]]` of point `p` is
/// `re[m][p] + i im[m][p]`, and `θ = exp(log_scale[p]) Ω`. Lanes `p ≥ len`
/// are unspecified, and so are rows `m ≥ chars.len()`.
#[derive(Debug, Clone)]
pub struct SelectedBlock {
    /// Points in this block (`1 ..= BLOCK`).
    pub len: usize,
    pub re: [[f64; BLOCK]; 16],
    pub im: [[f64; BLOCK]; 16],
    pub log_scale: [f64; BLOCK],
}

/// Real lattice coordinates of one block of genus-2 points, `z = x + τ y`,
/// one lane per point (structure of arrays): `x[i][p]`, `y[i][p]`.
#[derive(Debug, Clone, Default)]
#[repr(C, align(64))]
pub struct LatticeLanes {
    pub x: [[f64; BLOCK]; 2],
    pub y: [[f64; BLOCK]; 2],
}

impl ThetaPlan {
    /// Genus 2, values only, for the characteristics `chars` (FLINT indices,
    /// at most 16): the points `point(0) … point(npts − 1)` are evaluated
    /// [`BLOCK`] at a time and each block is handed to `sink(first, block)`
    /// while it is hot in cache. The lattice sum is shared by all
    /// characteristics (the class sums); only the requested ones are
    /// combined. Uses the vectorised kernel whenever the plan allows it
    /// (building its table on first use), else the per-point sum — no
    /// allocation per point either way.
    ///
    /// Errors: genus ≠ 2, an index ≥ 16, more than 16 indices, and those of
    /// [`ThetaPlan::eval_into`] for a point.
    pub fn eval_selected_g2(
        &self,
        npts: usize,
        point: impl Fn(usize) -> [Complex64; 2],
        chars: &[usize],
        sink: impl FnMut(usize, &SelectedBlock),
    ) -> Result<()> {
        self.eval_selected_g2_impl(
            npts,
            |i0, m, inp| {
                for p in 0..m {
                    inp.set(p, &self.reduce2::<false>(point(i0 + p))?);
                }
                Ok(())
            },
            &point,
            chars,
            sink,
        )
    }

    /// [`ThetaPlan::eval_selected_g2`] for points given by real lattice
    /// coordinates, `z = x + τ y` with `(x, y) = lattice(i)`: the reduction to
    /// the fundamental cell is then read off `y` (no solve with `Im τ`), which
    /// is most of the per-point cost outside the lattice sum.
    pub fn eval_selected_g2_lattice(
        &self,
        npts: usize,
        lattice: impl Fn(usize) -> ([f64; 2], [f64; 2]),
        chars: &[usize],
        sink: impl FnMut(usize, &SelectedBlock),
    ) -> Result<()> {
        self.eval_selected_g2_lattice_lanes(
            npts,
            |first, m, lanes| {
                for p in 0..m {
                    let (x, y) = lattice(first + p);
                    for i in 0..2 {
                        lanes.x[i][p] = x[i];
                        lanes.y[i][p] = y[i];
                    }
                }
            },
            chars,
            sink,
        )
    }

    /// [`ThetaPlan::eval_selected_g2_lattice`] with the coordinates of the
    /// points `first .. first + m` written a block at a time by
    /// `fill(first, m, lanes)` into lanes `0..m`, so that the caller can
    /// vectorise across the block too. The other lanes start at zero; `fill`
    /// may write them (their results are discarded), but keep them in
    /// `[−1, 1]`: a block whose coordinates all lie in `[−1, 1]` (as after a
    /// reduction modulo 2), on a plan whose `Re τ` cannot carry `Re z` past
    /// the representable range, is reduced for all its lanes at once,
    /// branch-free; any other goes point by point. Both give the same bits
    /// and the same errors.
    pub fn eval_selected_g2_lattice_lanes(
        &self,
        npts: usize,
        fill: impl Fn(usize, usize, &mut LatticeLanes),
        chars: &[usize],
        sink: impl FnMut(usize, &SelectedBlock),
    ) -> Result<()> {
        let lanes_of = |first: usize, m: usize| {
            let mut lanes = LatticeLanes::default();
            fill(first, m, &mut lanes);
            lanes
        };
        self.eval_selected_g2_impl(
            npts,
            |i0, m, inp| self.reduce2_lattice_lanes(&lanes_of(i0, m), m, inp),
            // Only without the batch kernel, where the per-point sum costs far
            // more than refilling the block.
            |i| {
                let first = i - i % BLOCK;
                let lanes = lanes_of(first, (npts - first).min(BLOCK));
                let p = i - first;
                std::array::from_fn(|k| {
                    let y = [lanes.y[0][p], lanes.y[1][p]];
                    Complex64::new(
                        lanes.x[k][p] + self.re_tau[2 * k] * y[0] + self.re_tau[2 * k + 1] * y[1],
                        self.y[2 * k] * y[0] + self.y[2 * k + 1] * y[1],
                    )
                })
            },
            chars,
            sink,
        )
    }

    fn eval_selected_g2_impl(
        &self,
        npts: usize,
        mut reduce_block: impl FnMut(usize, usize, &mut batch::ChunkIn) -> Result<()>,
        point: impl Fn(usize) -> [Complex64; 2],
        chars: &[usize],
        mut sink: impl FnMut(usize, &SelectedBlock),
    ) -> Result<()> {
        if self.g != 2 {
            return Err(Error::InvalidArgument {
                what: "eval_selected_g2",
                reason: format!("genus 2 only, the plan has genus {}", self.g),
            });
        }
        if chars.len() > 16 || chars.iter().any(|&c| c >= 16) {
            return Err(Error::InvalidArgument {
                what: "chars",
                reason: format!("at most 16 characteristic indices below 16, got {chars:?}"),
            });
        }
        let want = chars.iter().fold(0u16, |m, &c| m | (1 << c));
        let mut blk = SelectedBlock {
            len: 0,
            re: [[0.0; BLOCK]; 16],
            im: [[0.0; BLOCK]; 16],
            log_scale: [0.0; BLOCK],
        };
        let mut i0 = 0;
        if let Some(b2) = self.batch2.get_or_init(|| batch::Batch2::build(self)) {
            let mut sc = b2.scratch();
            let mut inp = batch::ChunkIn::default();
            while i0 < npts {
                let m = (npts - i0).min(BLOCK);
                reduce_block(i0, m, &mut inp)?;
                b2.eval_chunk(self, &inp, false, want, &mut sc);
                blk.len = m;
                blk.log_scale = inp.logs;
                for (k, &c) in chars.iter().enumerate() {
                    blk.re[k] = *sc.out_re[c];
                    blk.im[k] = *sc.out_im[c];
                }
                sink(i0, &blk);
                i0 += m;
            }
            return Ok(());
        }
        let mut ws = self.workspace();
        let mut vals = [Complex64::new(0.0, 0.0); 16];
        while i0 < npts {
            let m = (npts - i0).min(BLOCK);
            blk.re = [[0.0; BLOCK]; 16];
            blk.im = [[0.0; BLOCK]; 16];
            blk.log_scale = [0.0; BLOCK];
            for p in 0..m {
                let z = point(i0 + p);
                blk.log_scale[p] = self.eval_into(&z, &mut ws, &mut vals, &mut [], &mut [])?;
                for (k, &c) in chars.iter().enumerate() {
                    blk.re[k][p] = vals[c].re;
                    blk.im[k][p] = vals[c].im;
                }
            }
            blk.len = m;
            sink(i0, &blk);
            i0 += m;
        }
        Ok(())
    }
}
