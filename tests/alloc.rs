//! Memory stays O(samples): an integration allocates a fixed number of buffers
//! (output and scratch) whatever the number of steps — nothing per step.
//!
//! A counting global allocator (this test binary only) counts the allocations
//! made by the current thread while `integrate` runs.
//!
//! The full claim, 10^7 steps keeping 10^3 samples, is the ignored test; run it
//! with `cargo test --release --test alloc -- --ignored` (about a second in release).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use manakov::integrate::{integrate, Method, Options, MAX_STEPS};
use manakov::so4::FrahmTop;

struct Counting;

thread_local! {
    static COUNT: Cell<usize> = const { Cell::new(0) };
    static BYTES: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        let _ = BYTES.try_with(|c| c.set(c.get() + layout.size()));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        let _ = BYTES.try_with(|c| c.set(c.get() + new_size));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

const A: [f64; 4] = [0.3, 1.1, 2.0, 3.7];
const B: [f64; 4] = [0.5, -0.2, 1.4, 0.9];
const L0: [f64; 6] = [0.8, -0.3, 0.5, 1.1, -0.7, 0.2];

/// (allocations, bytes) made while integrating `steps` steps kept as `samples` samples.
fn count(method: Method, steps: usize, samples: usize) -> (usize, usize) {
    let top = FrahmTop::manakov(&A, &B).unwrap();
    let dt = 0.01;
    let every = dt * (steps / samples) as f64;
    let times: Vec<f64> = (1..=samples).map(|k| k as f64 * every).collect();
    let opts = Options {
        method,
        dt,
        rtol: 1e-10,
        atol: 1e-10,
        max_steps: MAX_STEPS as u64,
    };
    let (c0, b0) = (COUNT.with(Cell::get), BYTES.with(Cell::get));
    let tr = integrate(&top, &L0, 0.0, &times, &opts).unwrap();
    let counts = (COUNT.with(Cell::get) - c0, BYTES.with(Cell::get) - b0);
    assert_eq!(tr.t.len(), samples);
    if method.stages().is_some() {
        assert_eq!(tr.steps as usize, steps);
    }
    counts
}

#[test]
fn allocations_do_not_grow_with_the_number_of_steps() {
    for method in [
        Method::Gauss4,
        Method::Gauss6,
        Method::Gauss16,
        Method::Dopri5,
        Method::Dop853,
    ] {
        let few = count(method, 1_000, 100);
        let many = count(method, 20_000, 100);
        assert_eq!(few, many, "{method:?}: (allocations, bytes) differ");
        // A handful of buffers: output t and y, the state, the scratch.
        assert!(few.0 <= 16, "{method:?}: {} allocations", few.0);
    }
}

#[test]
#[ignore = "10^7 steps: run in release, `cargo test --release --test alloc -- --ignored`"]
fn ten_million_steps_thousand_samples() {
    let (allocs, bytes) = count(Method::Gauss4, 10_000_000, 1_000);
    println!("10^7 gauss4 steps, 10^3 samples: {allocs} allocations, {bytes} bytes");
    assert!(allocs <= 16);
    // Output 1000 × (6 + 1) doubles plus O(1) scratch.
    assert!(bytes < 1000 * 7 * 8 + 4096);
}
