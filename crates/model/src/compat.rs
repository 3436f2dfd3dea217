//! What the FMU's code would take from a newer standard library than Rust 1.63's, on which
//! the win64 build compiles (`scripts/build_win64.sh`, Debian's rustc).

use std::cell::UnsafeCell;
use std::mem::MaybeUninit;
use std::sync::Once;

/// `std::sync::OnceLock` (Rust 1.70), for statics: initialised once, never dropped.
pub struct OnceLock<T> {
    once: Once,
    value: UnsafeCell<MaybeUninit<T>>,
}

// SAFETY: the value is written once, inside `once`, before any reader sees it; readers get
// shared references only.
unsafe impl<T: Send + Sync> Sync for OnceLock<T> {}

impl<T> OnceLock<T> {
    pub const fn new() -> Self {
        OnceLock {
            once: Once::new(),
            value: UnsafeCell::new(MaybeUninit::uninit()),
        }
    }

    pub fn get_or_init(&self, init: impl FnOnce() -> T) -> &T {
        self.once.call_once(|| {
            // SAFETY: the only write, before `call_once` returns to anyone.
            unsafe { (*self.value.get()).write(init()) };
        });
        // SAFETY: written by the completed `call_once` above.
        unsafe { (*self.value.get()).assume_init_ref() }
    }
}

impl<T> Default for OnceLock<T> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::OnceLock;

    #[test]
    fn initialises_once() {
        static CELL: OnceLock<Vec<u32>> = OnceLock::new();
        let mut calls = 0;
        for _ in 0..3 {
            assert_eq!(
                CELL.get_or_init(|| {
                    calls += 1;
                    vec![1, 2, 3]
                }),
                &[1, 2, 3]
            );
        }
        assert_eq!(calls, 1);
        let threads: Vec<_> = (0..4)
            .map(|_| std::thread::spawn(|| CELL.get_or_init(Vec::new).len()))
            .collect();
        for t in threads {
            assert_eq!(t.join().unwrap(), 3);
        }
    }
}
