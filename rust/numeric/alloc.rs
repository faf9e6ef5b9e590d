//! The one path for allocations sized by user input.
//!
//! A plain `vec![0.0; n]`, `Vec::with_capacity(n)` or `collect()` aborts the
//! process when the allocation fails ("memory allocation of … bytes failed"):
//! from Python that is a crash, not an exception. Every buffer whose size a
//! caller chooses (a batch of states, sample times, points) goes through this
//! module instead:
//!
//! 1. [`check_size`]: the size against [`MAX_BYTES`], before any work — a
//!    request beyond it is [`Error::TooLarge`] naming the size, whatever the
//!    machine;
//! 2. [`try_vec`], [`try_collect`], [`try_map`]: the same check, then
//!    `try_reserve_exact` — a size within the budget that the machine cannot
//!    hold is [`Error::OutOfMemory`] naming the size.
//!
//! Python sees both as `MemoryError`, numpy's exception for an array it
//! cannot allocate.
//!
//! A binding checks the whole call (its copies of the input and its results)
//! with [`check_size`] before it copies anything; the allocations themselves
//! then go through the fallible constructors.

use crate::error::{Error, Result};
use crate::numeric::cancel::Cancel;

/// Most bytes one call may allocate for arrays sized by its input: 16 GiB.
///
/// Far above any array a computation here needs (10^8 samples of an so(4)
/// trajectory are 4.8 GB) and below what an address-space limit of a shared
/// machine allows, so that a mistyped size (`10**9` for `10**6`) is refused at
/// once with its size instead of filling the memory first.
pub const MAX_BYTES: usize = 1 << 34;

/// `count` items of `bytes_each` bytes for `what`, checked against [`MAX_BYTES`]:
/// the total in bytes, or [`Error::TooLarge`] (also when the product overflows).
pub fn check_size(what: &'static str, count: usize, bytes_each: usize) -> Result<usize> {
    match count.checked_mul(bytes_each) {
        Some(bytes) if bytes <= MAX_BYTES => Ok(bytes),
        _ => Err(Error::TooLarge {
            what,
            count,
            bytes: count as f64 * bytes_each as f64,
            limit: MAX_BYTES as f64,
        }),
    }
}

/// An empty vector with room for exactly `n` items, checked and fallible.
pub fn try_with_capacity<T>(what: &'static str, n: usize) -> Result<Vec<T>> {
    let bytes = check_size(what, n, std::mem::size_of::<T>())?;
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| Error::OutOfMemory {
        what,
        bytes: bytes as f64,
    })?;
    Ok(v)
}

/// `n` copies of `value`, checked and fallible (the `vec![value; n]` of this crate).
pub fn try_vec<T: Clone>(what: &'static str, n: usize, value: T) -> Result<Vec<T>> {
    let mut v = try_with_capacity(what, n)?;
    v.resize(n, value);
    Ok(v)
}

/// The items of `iter` (exactly `n` of them expected; more are still taken,
/// growing infallibly only past `n`), checked and fallible.
pub fn try_collect<T>(
    what: &'static str,
    n: usize,
    iter: impl IntoIterator<Item = T>,
) -> Result<Vec<T>> {
    let mut v = try_with_capacity(what, n)?;
    v.extend(iter);
    Ok(v)
}

/// Items between two cancellation checks for a map whose items cost about
/// `cost_ns` nanoseconds each: about a millisecond of work (`Cancel::check`
/// costs ~50 ns, so the check is free, and Ctrl-C is seen within the 0.5 s
/// promised), at least one item and at most 4096.
pub fn items_per_check(cost_ns: f64) -> usize {
    (1e6 / cost_ns.max(1.0)).clamp(1.0, 4096.0) as usize
}

/// `f` on every item, into a vector allocated by [`try_with_capacity`],
/// checking `cancel` every `every` items (see [`items_per_check`]); the first
/// error stops the map and is returned.
pub fn try_map<T, U>(
    what: &'static str,
    items: &[T],
    every: usize,
    cancel: &Cancel,
    mut f: impl FnMut(&T) -> Result<U>,
) -> Result<Vec<U>> {
    let mut out = try_with_capacity(what, items.len())?;
    for chunk in items.chunks(every.max(1)) {
        cancel.check()?;
        for x in chunk {
            out.push(f(x)?);
        }
    }
    Ok(out)
}

/// `f(row, out_row)` on every row of `m` entries of `input` (row-major), the
/// rows of `k` results in a vector allocated by [`try_vec`] (row-major,
/// `input.len() / m` rows), checking `cancel` every `every` rows.
pub fn try_map_rows<T, U: Clone + Default>(
    what: &'static str,
    input: &[T],
    m: usize,
    k: usize,
    every: usize,
    cancel: &Cancel,
    mut f: impl FnMut(&[T], &mut [U]) -> Result<()>,
) -> Result<Vec<U>> {
    let rows = input.len().checked_div(m).unwrap_or(0);
    let mut out = try_vec(what, rows.saturating_mul(k), U::default())?;
    if rows == 0 || k == 0 {
        return Ok(out);
    }
    let every = every.max(1);
    for (ins, outs) in input.chunks(m * every).zip(out.chunks_mut(k * every)) {
        cancel.check()?;
        for (x, o) in ins.chunks(m).zip(outs.chunks_mut(k)) {
            f(x, o)?;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_over_the_budget_are_refused_before_allocating() {
        assert_eq!(check_size("x", 2, 8), Ok(16));
        assert_eq!(check_size("x", MAX_BYTES / 8, 8), Ok(MAX_BYTES));
        let e = check_size("l", MAX_BYTES / 8 + 1, 8).unwrap_err();
        assert!(matches!(e, Error::TooLarge { what: "l", .. }), "{e:?}");
        assert!(e.to_string().contains("17179869192 bytes"), "{e}");
        // An overflowing product is over the budget too, never a wrap-around.
        assert!(check_size("x", usize::MAX, 16).is_err());
        assert!(try_vec::<f64>("x", usize::MAX / 4, 0.0).is_err());
        assert!(try_with_capacity::<u8>("x", MAX_BYTES + 1).is_err());
    }

    #[test]
    fn the_checked_constructors_build_what_vec_builds() {
        assert_eq!(try_vec("x", 3, 1.5).unwrap(), vec![1.5; 3]);
        assert_eq!(try_collect("x", 3, 0..3).unwrap(), vec![0, 1, 2]);
        let c = Cancel::never();
        let sq = try_map("x", &[1, 2, 3], 2, &c, |&v| Ok(v * v)).unwrap();
        assert_eq!(sq, vec![1, 4, 9]);
        let rows = try_map_rows("x", &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 2, 1, 2, &c, |r, o| {
            o[0] = r[0] + r[1];
            Ok(())
        });
        assert_eq!(rows.unwrap(), vec![3.0, 7.0, 11.0]);
        let e = try_map("x", &[1, 2, 3], 1, &c, |&v| {
            if v == 2 {
                Err(Error::Interrupted)
            } else {
                Ok(v)
            }
        });
        assert_eq!(e, Err(Error::Interrupted));
    }

    #[test]
    fn a_map_stops_once_cancelled() {
        let c = Cancel::never();
        c.cancel();
        let items = vec![0u8; 10];
        assert_eq!(
            try_map("x", &items, 4, &c, |&v| Ok(v)),
            Err(Error::Interrupted)
        );
        assert_eq!(items_per_check(5.0), 4096);
        assert_eq!(items_per_check(1e5), 10);
        assert_eq!(items_per_check(1e9), 1);
    }
}
