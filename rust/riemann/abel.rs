//! The Abel–Jacobi map `u(P) = A^{-1} ∫_{P_0}^{P} ω`: integrals from the
//! branch points along the tree and from a branch point or from infinity to
//! the point (the route with the best-conditioned quadrature), its reduction
//! modulo the lattice, and the half periods of the branch points.

use super::*;

impl HyperellipticCurve {
    /// Fills `u_branch` (tree paths from `P0`) and, for even `n`, `u_inf`.
    pub(super) fn base_points(&mut self) -> Result<()> {
        let (n, g) = (self.e.len(), self.g);
        let zero = vec![C::new(0.0, 0.0); g];
        // The ray to ∞ starts at the branch point farthest from the centre and
        // points away from it: every other branch point lies in the disc of
        // that radius, i.e. behind the ray's start.
        let r = (0..n)
            .max_by(|&i, &j| {
                (self.e[i] - self.center)
                    .norm()
                    .total_cmp(&(self.e[j] - self.center).norm())
            })
            .unwrap_or(0);
        let d = (self.e[r] - self.center) / (self.e[r] - self.center).norm();
        let len = 2.0
            * self
                .e
                .iter()
                .map(|v| (v - self.e[r]).norm())
                .fold(0.0, f64::max);
        let xr = self.e[r] + d * len;
        let yr = self.y_int(xr, 1);
        let part1 = self.path_from_branch(r, xr, yr, None)?;
        let (part2, lam) = self.to_infinity(self.e[r], xr, yr, None)?;
        let ray: Vec<C> = (0..g).map(|i| part1[i] + part2[i]).collect(); // ∫_{e_r}^{∞} ω
        let root = if n % 2 == 1 { r } else { 0 };
        let mut u = vec![zero.clone(); n];
        let mut done = vec![false; n];
        u[root] = if n % 2 == 1 {
            ray.iter().map(|v| -v).collect()
        } else {
            zero.clone()
        };
        done[root] = true;
        let mut stack = vec![root];
        while let Some(v) = stack.pop() {
            for (ei, &(p, q)) in self.tree.iter().enumerate() {
                let half: Vec<C> = self.edge_periods[ei].iter().map(|x| 0.5 * x).collect();
                if p == v && !done[q] {
                    u[q] = (0..g).map(|i| u[p][i] + half[i]).collect();
                    done[q] = true;
                    stack.push(q);
                } else if q == v && !done[p] {
                    u[p] = (0..g).map(|i| u[q][i] - half[i]).collect();
                    done[p] = true;
                    stack.push(p);
                }
            }
        }
        if n % 2 == 0 {
            // ∫_{P0}^{∞_λ} = u(e_r) + ray; u(∞−) = −u(∞+) (P0 is a Weierstrass point).
            let s = if lam.re > 0.0 { 1.0 } else { -1.0 };
            self.u_inf = (0..g).map(|i| s * (u[r][i] + ray[i])).collect();
        }
        self.u_branch = u;
        Ok(())
    }

    /// `∫_{e_k}^{(x, y)} ω` (unnormalised) along the straight segment, on the
    /// sheet of `y`. With `x(σ) = e + (x − e)σ²`, `y = σ q Π_{m≠k} φ_m`,
    /// `q² = x − e`: `dx/y = 2 q dσ / Π φ_m(σ²)`, analytic on `[0, 1]`.
    /// `fhs`: the route's focal half sum ([`Self::branch_quality`]) if the
    /// caller has it.
    pub(super) fn path_from_branch(
        &self,
        k: usize,
        x: C,
        y: C,
        known: Option<(&[f64], f64)>,
    ) -> Result<Row> {
        self.path_from_branch_dx(k, x - self.e[k], y, known)
    }

    /// [`Self::path_from_branch`] with the offset `dx = x − e_k` given: near
    /// `e_k` a double `x` fixes `dx` only to `u |x|` absolute, and the
    /// integral (in the local parameter `√dx`) inherits `u |x| / |dx|`
    /// relative; an offset carried separately keeps it to roundoff.
    fn path_from_branch_dx(
        &self,
        k: usize,
        dx: C,
        y: C,
        known: Option<(&[f64], f64)>,
    ) -> Result<Row> {
        let n = self.e.len();
        let ek = self.e[k];
        let x = ek + dx;
        let mut out = ZERO_ROW;
        if dx == C::new(0.0, 0.0) {
            return Ok(out);
        }
        let mut dist_buf = [0.0; MAX_N];
        let (dist, fhs) = match known {
            Some(v) => v,
            None => {
                for (d, &em) in dist_buf.iter_mut().zip(&self.e) {
                    *d = (x - em).modulus();
                }
                (&dist_buf[..n], self.branch_quality(k, &dist_buf[..n]))
            }
        };
        let q = sqrt_principal(dx);
        // Stack buffers: this is the per-point hot path. Factor m ≠ k is
        // a_m + s² dx, a_m = e_k − e_m, with |a_m| = |e_k − e_m| and
        // |a_m + dx| = |x − e_m|.
        let (mut a, b) = ([dx; MAX_N], [dx; MAX_N]);
        let (mut abs_a, mut abs_e) = ([0.0; MAX_N], [0.0; MAX_N]);
        let mut ns = 0;
        for (m, &em) in self.e.iter().enumerate() {
            if m == k {
                continue;
            }
            a[ns] = ek - em;
            abs_a[ns] = self.e_dist[k * n + m];
            abs_e[ns] = dist[m];
            ns += 1;
        }
        let prod = SqrtProduct::new(&a[..ns], &b[..ns], &abs_a[..ns], &abs_e[..ns]);
        let unrot = prod.unrot();
        let y1 = q * unrot * prod.rotated(1.0);
        let sign = if (y * y1.conj()).re < 0.0 { -1.0 } else { 1.0 };
        let acc = &mut out[..self.g];
        let integrand = |s: f64, w: f64, acc: &mut [C]| {
            let s2 = s * s;
            let xs = ek + dx * s2;
            let mut f = prod.inv_rotated(s2) * w;
            for v in acc.iter_mut() {
                *v += f;
                f *= xs;
            }
        };
        // Singularities ±√t_m come in pairs: the ellipse of [−1, 1] decides.
        let nn = nodes_for(fhs.acosh());
        if nn <= quad::GL_MAX as f64 {
            quad::integrate_even(nn as usize, acc, integrand);
        } else {
            let mut sing = [C::new(0.0, 0.0); 2 * MAX_N];
            for (i, &am) in a[..ns].iter().enumerate() {
                let s = sqrt_principal(-am / dx);
                sing[2 * i] = s;
                sing[2 * i + 1] = -s;
            }
            let mut pieces: Vec<Piece> = Vec::new();
            quad::plan_pieces(&sing[..2 * ns], &mut pieces)?;
            quad::integrate(&pieces, acc, integrand);
        }
        let fac = 2.0 * sign * q / unrot;
        acc.iter_mut().for_each(|v| *v *= fac);
        Ok(out)
    }

    /// `(∫_{(x, y)}^{∞_λ} ω, λ)` along the ray from `c` through `x` (unnormalised).
    /// With `X = x − c`, `x(τ) = c + X/τ²`, `y = τ^{−n} Π ψ_m(τ²)`,
    /// `ψ_m² = X + τ²(c − e_m)`:
    /// `∫_x^∞ ω_i = (2X/s) ∫_0^1 (cτ² + X)^{i−1} τ^{n−2i−1} / Πψ_m dτ`, `s = ±1`
    /// the sheet. `λ = s Πψ_m(0) / X^{g+1}` is `±1` for even `n` (which of
    /// `∞±` the ray reaches); for odd `n` it is meaningless and returned as 1.
    /// `fhs`: the route's focal half sum (odd `n`, [`Self::infinity_quality`]
    /// for `c` the centre) if the caller has it.
    fn to_infinity(&self, c: C, x: C, y: C, known: Option<(&[f64], f64)>) -> Result<(Row, C)> {
        let (n, g) = (self.e.len(), self.g);
        let odd = n % 2 == 1;
        let xx = x - c;
        let ax = xx.modulus();
        let mut dist_buf = [0.0; MAX_N];
        let dist = match known {
            Some((d, _)) => d,
            None => {
                for (d, &em) in dist_buf.iter_mut().zip(&self.e) {
                    *d = (x - em).modulus();
                }
                &dist_buf[..n]
            }
        };
        // Factor m is X + τ² (c − e_m): |X| and |X + c − e_m| = |x − e_m|.
        let mut b = [xx; MAX_N];
        for (bm, &em) in b.iter_mut().zip(&self.e) {
            *bm = c - em;
        }
        let a = [xx; MAX_N];
        let prod = SqrtProduct::new(&a[..n], &b[..n], &[ax; MAX_N][..n], dist);
        let unrot = prod.unrot();
        let y1 = unrot * prod.rotated(1.0);
        let sign = if (y * y1.conj()).re < 0.0 { -1.0 } else { 1.0 };
        let lam = if odd {
            C::new(1.0, 0.0)
        } else {
            let y0 = unrot * prod.rotated(0.0);
            sign * y0 / xx.powi(g as i32 + 1)
        };
        let mut out = ZERO_ROW;
        let acc = &mut out[..g];
        // τ^{n−2i−1} for i = 1..g: τ^{n−2g−1} (τ⁰ or τ¹) times falling powers of τ².
        let t_odd = !odd;
        let integrand = |t: f64, w: f64, acc: &mut [C]| {
            let t2 = t * t;
            let xs = c * t2 + xx;
            let inv = prod.inv_rotated(t2) * w;
            let mut tp = if t_odd { t } else { 1.0 };
            let mut tps = [0.0f64; MAX_GENUS + 1];
            for i in (0..g).rev() {
                tps[i] = tp;
                tp *= t2;
            }
            let mut xp = inv;
            for (i, v) in acc.iter_mut().enumerate() {
                *v += xp * tps[i];
                xp *= xs;
            }
        };
        let lr = if odd {
            match known {
                Some((_, fhs)) => fhs,
                None => {
                    let mut best = f64::INFINITY;
                    for (&bm, &dm) in b[..n].iter().zip(dist) {
                        let ab = bm.modulus();
                        if ab > 0.0 {
                            best = best.min(focal_half_sum_sqrt(ax / ab, dm / ab));
                        }
                    }
                    best
                }
            }
            .acosh()
        } else {
            0.0
        };
        let nn = nodes_for(lr);
        if odd && nn <= quad::GL_MAX as f64 {
            quad::integrate_even(nn as usize, acc, integrand);
        } else {
            let mut sing = [C::new(0.0, 0.0); 2 * MAX_N];
            let mut ns = 0;
            for &bm in &b[..n] {
                if bm != C::new(0.0, 0.0) {
                    let s = sqrt_principal(-xx / bm);
                    sing[ns] = s;
                    sing[ns + 1] = -s;
                    ns += 2;
                }
            }
            let mut pieces: Vec<Piece> = Vec::new();
            quad::plan_pieces(&sing[..ns], &mut pieces)?;
            quad::integrate(&pieces, acc, integrand);
        }
        let fac = 2.0 * sign * xx / unrot;
        acc.iter_mut().for_each(|v| *v *= fac);
        Ok((out, lam))
    }
}

/// Branch points tried as the start of an Abel path (the nearest ones).
const ROUTE_CANDIDATES: usize = 3;

/// Rows at least this long are split over rayon's pool in [`HyperellipticCurve::abel_batch`]
/// (~1 ms of work, well above the pool's wake-up cost).
const PARALLEL_MIN_POINTS: usize = 1024;

impl HyperellipticCurve {
    /// Checks that `(x, y)` lies on the curve to [`ON_CURVE_RTOL`]:
    /// `|y² − R(x)| ≤ ON_CURVE_RTOL · Π_k (|x| + |e_k|)`, evaluated divided by
    /// `|R(x)|` as `|q² − 1| ≤ ON_CURVE_RTOL · Π_k (|x| + |e_k|)/|x − e_k|` with
    /// `q = y / Π_k √(x − e_k)` (factor by factor, so nothing overflows before
    /// `y` itself does).
    pub fn check_point(&self, x: C, y: C) -> Result<()> {
        self.check_point_int(self.x_in(x), self.y_in(y))
    }

    /// [`Self::check_point`] in the internal coordinate.
    fn check_point_int(&self, x: C, y: C) -> Result<()> {
        if !is_finite_c(x) || !is_finite_c(y) {
            return Err(Error::InvalidArgument {
                what: "point",
                reason: format!("x = {x}, y = {y} must be finite"),
            });
        }
        let mut dist = [0.0; MAX_N];
        for (d, &em) in dist.iter_mut().zip(&self.e) {
            *d = (x - em).modulus();
        }
        self.check_point_with(x, y, &dist[..self.e.len()])
    }

    /// [`Self::check_point`] for finite `x, y` given `dist[k] = |x − e_k|`.
    /// Where `|R(x)|` and `|y|²` are well inside the double range the ratio
    /// `q² = y²/R(x)` is formed directly (one complex product chain instead
    /// of `n` square roots); otherwise factor by factor.
    fn check_point_with(&self, x: C, y: C, dist: &[f64]) -> Result<()> {
        if let Some(k) = self.e.iter().position(|&ek| x == ek) {
            let scale: f64 = self.e.iter().map(|ek| x.norm() + ek.norm()).product();
            if y.norm() > (ON_CURVE_RTOL * scale).sqrt() {
                return Err(Error::InvalidArgument {
                    what: "point",
                    reason: format!("x = e[{k}] is a branch point: y must be 0, got {y}"),
                });
            }
            return Ok(());
        }
        let ax = x.modulus();
        let mut bound = ON_CURVE_RTOL;
        let mut r = C::new(1.0, 0.0);
        for ((&ek, &aek), &d) in self.e.iter().zip(&self.e_abs).zip(dist) {
            r *= x - ek;
            bound *= (ax + aek) / d;
        }
        let (rn, yn) = (r.norm_sqr(), y.norm_sqr());
        let dev = if rn > 1e-200 && rn < 1e200 && yn < 1e200 {
            (crate::numeric::complex::cdiv(y * y, r) - 1.0).norm()
        } else {
            let mut q = y;
            for &ek in &self.e {
                q /= sqrt_principal(x - ek);
            }
            if !is_finite_c(q) {
                return Err(Error::InvalidArgument {
                    what: "point",
                    reason: format!(
                        "x = {x}: |x| is too large for y = R(x)^(1/2) in double precision"
                    ),
                });
            }
            (q * q - 1.0).norm()
        };
        if dev > bound {
            return Err(Error::InvalidArgument {
                what: "point",
                reason: format!(
                    "(x, y) = ({x}, {y}) is not on the curve: |y² − R(x)| / |R(x)| = {dev:e} > \
                     {ON_CURVE_RTOL:e} · Π(|x| + |e_k|)/|R(x)| = {bound:e}"
                ),
            });
        }
        Ok(())
    }

    /// Focal half sum `(|z−1| + |z+1|)/2` of the worst singularity of the
    /// route from `e_k` (larger is better): the integrand is even with
    /// singularities `±√w_m`, `w_m = (e_m − e_k)/(x − e_k)`, and
    /// [`focal_half_sum_sqrt`] needs only `|w_m|` and `|w_m − 1|`, i.e. the
    /// distances `|e_m − e_k|` (per curve) and `dist[m] = |x − e_m|`.
    fn branch_quality(&self, k: usize, dist: &[f64]) -> f64 {
        let n = self.e.len();
        let dk = dist[k];
        let row = &self.e_dist[k * n..(k + 1) * n];
        let mut best = f64::INFINITY;
        for m in 0..n {
            if m != k {
                best = best.min(focal_half_sum_sqrt(row[m] / dk, dist[m] / dk));
            }
        }
        best
    }

    /// As [`Self::branch_quality`] for the ray from the centre `c` through
    /// `x`: singularities at `τ² = w_m`, `w_m = (x − c)/(e_m − c)`. Odd `n`:
    /// even integrand, pairs `±√w_m` (ellipse of `[−1, 1]`). Even `n`: the
    /// integrand on `[0, 1]` has singularities `±√w_m`, mapped to `[−1, 1]` by
    /// `2z − 1`: `(|2z − 2| + |2z|)/2 = |z| + |z − 1|`, so the worse of `±√w`
    /// gives `|z| + min(|z − 1|, |z + 1|)`, where `|z ∓ 1|` are the roots of
    /// `a² + b² = 2|w| + 2`, `ab = |w − 1|`. A branch point at `c` imposes
    /// nothing (its factor is constant along the ray).
    fn infinity_quality(&self, x: C, dist: &[f64]) -> f64 {
        let dc = (x - self.center).modulus();
        let odd = self.e.len() % 2 == 1;
        let mut best = f64::INFINITY;
        for (&cm, &dm) in self.c_dist.iter().zip(dist) {
            if cm == 0.0 {
                continue;
            }
            let (aw, aw1) = (dc / cm, dm / cm);
            let v = if odd {
                focal_half_sum_sqrt(aw, aw1)
            } else {
                let sum = (2.0 * (aw + 1.0 + aw1)).sqrt();
                let diff = (2.0 * (aw + 1.0 - aw1)).max(0.0).sqrt();
                (aw.sqrt() + 0.5 * (sum - diff)).max(1.0)
            };
            best = best.min(v);
        }
        best
    }

    /// `∫_{P0}^{(x, y)} ω`, unnormalised, along the best route (no point check).
    pub(super) fn abel_unnormalised(&self, x: C, y: C) -> Result<Row> {
        let n = self.e.len();
        let mut dist = [0.0; MAX_N];
        for (d, &em) in dist.iter_mut().zip(&self.e) {
            *d = (x - em).modulus();
        }
        self.abel_raw(x, y, &dist[..n])
    }

    /// [`Self::abel_unnormalised`] given `dist[m] = |x − e_m|`.
    fn abel_raw(&self, x: C, y: C, dist: &[f64]) -> Result<Row> {
        let g = self.g;
        let mut out = ZERO_ROW;
        if let Some(k) = self.e.iter().position(|&ek| ek == x) {
            out[..g].copy_from_slice(&self.u_branch[k]);
            return Ok(out);
        }
        // Candidates: the ray from ∞ and the segments from the ROUTE_CANDIDATES
        // nearest branch points (a far start is never better: its segment
        // passes the nearer ones). Any route is exact to the target; the
        // choice only sets the node count.
        let mut near = [(f64::INFINITY, 0usize); ROUTE_CANDIDATES];
        for (k, &d) in dist.iter().enumerate() {
            if d < near[ROUTE_CANDIDATES - 1].0 {
                let mut i = ROUTE_CANDIDATES - 1;
                while i > 0 && near[i - 1].0 > d {
                    near[i] = near[i - 1];
                    i -= 1;
                }
                near[i] = (d, k);
            }
        }
        let mut best = (Route::Infinity, self.infinity_quality(x, dist));
        for &(d, k) in &near {
            if d.is_finite() {
                let q = self.branch_quality(k, dist);
                if q > best.1 {
                    best = (Route::Branch(k), q);
                }
            }
        }
        let first = match self.route_into(best.0, best.1, x, y, dist, &mut out) {
            Ok(()) => return Ok(out),
            Err(e @ Error::InvalidArgument { what: "path", .. }) => e,
            Err(e) => return Err(e),
        };
        // The best route's path runs within rounding of another branch point
        // (a segment planned onto a singularity): the others, best first.
        // Every route is exact to the target, so a fallback changes nothing
        // but the path.
        let mut others = [(Route::Infinity, f64::NEG_INFINITY); ROUTE_CANDIDATES];
        let mut no = 0;
        if !matches!(best.0, Route::Infinity) {
            others[no] = (Route::Infinity, self.infinity_quality(x, dist));
            no += 1;
        }
        for &(d, k) in &near {
            if d.is_finite() && !matches!(best.0, Route::Branch(b) if b == k) {
                others[no] = (Route::Branch(k), self.branch_quality(k, dist));
                no += 1;
            }
        }
        let others = &mut others[..no];
        others.sort_by(|p, q| q.1.partial_cmp(&p.1).unwrap_or(std::cmp::Ordering::Equal));
        for &(route, quality) in others.iter() {
            match self.route_into(route, quality, x, y, dist, &mut out) {
                Ok(()) => return Ok(out),
                Err(Error::InvalidArgument { what: "path", .. }) => {}
                Err(e) => return Err(e),
            }
        }
        Err(first)
    }

    /// The Abel integral over one route (see [`Self::abel_raw`]) into `out`.
    fn route_into(
        &self,
        route: Route,
        quality: f64,
        x: C,
        y: C,
        dist: &[f64],
        out: &mut Row,
    ) -> Result<()> {
        let g = self.g;
        match route {
            Route::Branch(k) => {
                let v = self.path_from_branch(k, x, y, Some((dist, quality)))?;
                for i in 0..g {
                    out[i] = self.u_branch[k][i] + v[i];
                }
            }
            Route::Infinity => {
                let (v, lam) = self.to_infinity(self.center, x, y, Some((dist, quality)))?;
                let s = if self.e.len() % 2 == 1 || lam.re > 0.0 {
                    1.0
                } else {
                    -1.0
                };
                for i in 0..g {
                    out[i] = s * self.u_inf[i] - v[i];
                }
            }
        }
        Ok(())
    }

    /// The integral `∫_{(x0,y0)}^{(x, y)} ω` (unnormalised) along a path
    /// through `∞` or the branch point `k` (`route = Some(k)`), for tests of
    /// path independence.
    pub fn abel_via(&self, x: C, y: C, route: Option<usize>) -> Result<Vec<C>> {
        let (x, y) = (self.x_in(x), self.y_in(y));
        self.check_point_int(x, y)?;
        let raw: Row = match route {
            Some(k) if k < self.e.len() => {
                let v = self.path_from_branch(k, x, y, None)?;
                std::array::from_fn(|i| {
                    if i < self.g {
                        self.u_branch[k][i] + v[i]
                    } else {
                        v[i]
                    }
                })
            }
            Some(k) => {
                return Err(Error::InvalidArgument {
                    what: "route",
                    reason: format!("branch point index {k} out of range"),
                })
            }
            None => {
                let (v, lam) = self.to_infinity(self.center, x, y, None)?;
                let s = if self.e.len() % 2 == 1 || lam.re > 0.0 {
                    1.0
                } else {
                    -1.0
                };
                std::array::from_fn(|i| {
                    if i < self.g {
                        s * self.u_inf[i] - v[i]
                    } else {
                        v[i]
                    }
                })
            }
        };
        Ok(self.normalise(&raw))
    }

    pub(super) fn normalise(&self, raw: &[C]) -> Vec<C> {
        let mut out = ZERO_ROW;
        self.normalise_into(raw, &mut out[..self.g]);
        out[..self.g].to_vec()
    }

    #[inline]
    fn normalise_into(&self, raw: &[C], out: &mut [C]) {
        let g = self.g;
        for (i, o) in out.iter_mut().enumerate().take(g) {
            *o = (0..g).map(|j| self.a_inv[(i, j)] * raw[j]).sum();
        }
    }

    /// The Abel map `u(P) = A^{-1} ∫_{P0}^{P} ω` of `P = (x, y)` (`y` picks the
    /// sheet), `P0 = ∞` (odd `n`) or `e_1` (even `n`), modulo the lattice.
    ///
    /// Errors: `(x, y)` not on the curve to [`ON_CURVE_RTOL`], non-finite input.
    pub fn abel(&self, x: C, y: C) -> Result<Vec<C>> {
        let mut out = ZERO_ROW;
        self.abel_into(self.x_in(x), self.y_in(y), &mut out[..self.g])?;
        Ok(out[..self.g].to_vec())
    }

    /// The Abel map of the point `(x, y)` close to the branch point `e_k`,
    /// given its offset `dx = x − e_k` to full relative accuracy: the
    /// integral runs from `e_k` in the local parameter `√dx`, so the result
    /// keeps roundoff where [`Self::abel`] of the double `x` loses
    /// `u |x| / |x − e_k|` (u the unit roundoff). `y` picks the sheet.
    ///
    /// Errors: `k` out of range, non-finite input, `(e_k + dx, y)` not on the
    /// curve.
    pub fn abel_near_branch(&self, k: usize, dx: C, y: C) -> Result<Vec<C>> {
        if k >= self.e.len() {
            return Err(Error::InvalidArgument {
                what: "branch point index",
                reason: format!("{k} is out of range (0..{})", self.e.len()),
            });
        }
        let (dx, y) = (self.x_in(dx), self.y_in(y));
        let x = self.e[k] + dx;
        self.check_point_int(x, y)?;
        let v = self.path_from_branch_dx(k, dx, y, None)?;
        let raw: Row = std::array::from_fn(|i| {
            if i < self.g {
                self.u_branch[k][i] + v[i]
            } else {
                v[i]
            }
        });
        let u = self.normalise(&raw);
        // A path through (or within rounding of) another branch point can make
        // the quadrature NaN without tripping its own distance test: an error,
        // as for the paths that do trip it, never a NaN returned.
        if !u.iter().all(|&c| is_finite_c(c)) {
            return Err(Error::InvalidArgument {
                what: "path",
                reason: format!(
                    "the integral from branch point {k} to x = e_{k} + {} is not finite in \
                     double precision (the path passes too close to another branch point); \
                     use abel(x, y) for points far from e_{k}",
                    crate::error::cnum(dx)
                ),
            });
        }
        Ok(u)
    }

    /// [`Self::abel`] into `out` (length `g`), without allocating, of the point
    /// `(x, y)` in the internal coordinate: the distances `|x − e_m|` serve the
    /// point check, the route choice and the node count.
    fn abel_into(&self, x: C, y: C, out: &mut [C]) -> Result<()> {
        let n = self.e.len();
        if !is_finite_c(x) || !is_finite_c(y) {
            return self.check_point_int(x, y);
        }
        let mut dist = [0.0; MAX_N];
        for (d, &em) in dist.iter_mut().zip(&self.e) {
            *d = (x - em).modulus();
        }
        self.check_point_with(x, y, &dist[..n])?;
        let raw = self.abel_raw(x, y, &dist[..n])?;
        self.normalise_into(&raw, out);
        Ok(())
    }

    /// [`Self::abel`] of `N` points into `out` (row-major `(N, g)`); rayon for
    /// large batches.
    pub fn abel_batch(&self, x: &[C], y: &[C], out: &mut [C]) -> Result<()> {
        let g = self.g;
        if x.len() != y.len() || out.len() != x.len() * g {
            return Err(Error::Shape {
                what: "abel_batch",
                expected: format!("x, y of equal length N and out of N*{g}"),
                got: format!("{}, {}, {}", x.len(), y.len(), out.len()),
            });
        }
        let one = |(i, row): (usize, &mut [C])| -> Result<()> {
            self.abel_into(self.x_in(x[i]), self.y_in(y[i]), row)
        };
        if x.len() >= PARALLEL_MIN_POINTS {
            use rayon::prelude::*;
            out.par_chunks_mut(g).enumerate().try_for_each(one)
        } else {
            out.chunks_mut(g).enumerate().try_for_each(one)
        }
    }

    /// Real lattice coordinates `(α, β)` of `z = α + τ β`.
    pub fn lattice_coordinates(&self, z: &[C]) -> (Vec<f64>, Vec<f64>) {
        let g = self.g;
        let beta: Vec<f64> = (0..g)
            .map(|i| (0..g).map(|j| self.im_tau_inv[(i, j)] * z[j].im).sum())
            .collect();
        let alpha: Vec<f64> = (0..g)
            .map(|i| z[i].re - (0..g).map(|j| self.tau[(i, j)].re * beta[j]).sum::<f64>())
            .collect();
        (alpha, beta)
    }

    /// `z = α + τ β` of real lattice coordinates `(α, β)` (the inverse of
    /// [`Self::lattice_coordinates`]).
    pub fn lattice_point(&self, alpha: &[f64], beta: &[f64]) -> Vec<C> {
        (0..self.g)
            .map(|i| (0..self.g).fold(C::new(alpha[i], 0.0), |z, j| z + self.tau[(i, j)] * beta[j]))
            .collect()
    }

    /// `z` reduced modulo `Z^g + τ Z^g` to `α + τβ` with `α, β ∈ [−1/2, 1/2]`.
    pub fn reduce(&self, z: &[C]) -> Vec<C> {
        let g = self.g;
        let (alpha, beta) = self.lattice_coordinates(z);
        (0..g)
            .map(|i| {
                let mut v = z[i] - alpha[i].round();
                for j in 0..g {
                    v -= self.tau[(i, j)] * beta[j].round();
                }
                v
            })
            .collect()
    }

    /// The characteristic `[a; b]` of a half period `z ≡ (b + τa)/2`.
    pub fn half_period_char(&self, z: &[C]) -> Result<(Vec<u8>, Vec<u8>)> {
        let (alpha, beta) = self.lattice_coordinates(z);
        let mut a = Vec::with_capacity(self.g);
        let mut b = Vec::with_capacity(self.g);
        for i in 0..self.g {
            let (ta, tb) = (2.0 * beta[i], 2.0 * alpha[i]);
            if (ta - ta.round()).abs() > CHAR_TOL || (tb - tb.round()).abs() > CHAR_TOL {
                return Err(Error::InvalidArgument {
                    what: "half period",
                    reason: format!("2β = {ta}, 2α = {tb} are not integers: not a half period"),
                });
            }
            a.push((ta.round() as i64).rem_euclid(2) as u8);
            b.push((tb.round() as i64).rem_euclid(2) as u8);
        }
        Ok((a, b))
    }

    /// The half period `(b + τ a)/2` of a characteristic.
    pub fn half_period(&self, a: &[u8], b: &[u8]) -> Vec<C> {
        let g = self.g;
        (0..g)
            .map(|i| {
                let mut v = C::new(0.5 * f64::from(b[i]), 0.0);
                for j in 0..g {
                    v += 0.5 * self.tau[(i, j)] * f64::from(a[j]);
                }
                v
            })
            .collect()
    }

    /// `u(e_k)` (0-based `k`, unreduced; `k = n` is `∞` for odd `n`, `u = 0`).
    pub fn abel_branch_point(&self, k: usize) -> Result<Vec<C>> {
        if k < self.e.len() {
            Ok(self.normalise(&self.u_branch[k]))
        } else if k == self.e.len() && self.e.len() % 2 == 1 {
            Ok(vec![C::new(0.0, 0.0); self.g])
        } else {
            Err(Error::InvalidArgument {
                what: "k",
                reason: format!(
                    "branch point index {k} out of range 0..{} ({} for ∞ when n is odd)",
                    self.e.len(),
                    self.e.len()
                ),
            })
        }
    }

    /// `η(e_k)`: `u(e_k) ≡ (b + τ a)/2` modulo the lattice, for the 0-based
    /// index `k` (`e_{k+1}`); `k = n` is `∞` for odd `n` (`η(∞) = 0`, the base
    /// point).
    ///
    /// Errors: an index out of range, those of the Abel map.
    pub fn branch_char(&self, k: usize) -> Result<(Vec<u8>, Vec<u8>)> {
        self.half_period_char(&self.abel_branch_point(k)?)
    }

    /// The half period `(b + τa)/2` of `η(e_k)` (reduced representative).
    pub fn branch_half_period(&self, k: usize) -> Result<Vec<C>> {
        let (a, b) = self.branch_char(k)?;
        Ok(self.half_period(&a, &b))
    }
}
