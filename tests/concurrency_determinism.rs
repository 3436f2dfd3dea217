//! Issue 5, concurrency, determinism and FMU state, through the exported `fmi2*` symbols:
//! * 8 instances stepped from 8 threads give bit-identical results to the same instances
//!   stepped serially (and to a second serial run: determinism);
//! * a serialized state continues bit-identically in another instance (another process:
//!   fmu_tests/test_state.py::test_serialized_state_in_fresh_process);
//! * a serialized state from another model version, and every single-byte corruption and
//!   truncation of a serialized state, is rejected with a message, the instance unchanged.
//!
//! Bounded for CI: JETPIPE_THREADS_SECONDS (default 1) simulated seconds per instance.

mod common;

use std::ptr::null_mut;
use std::sync::Barrier;
use std::time::Instant;

use common::*;
use fmi2::fmu_state::crc32;
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::vr;

const H: f64 = 0.01;

/// Instance `k`'s inputs at step `n`: its own random commands and stopper positions.
fn inputs(k: usize, n: usize) -> (f64, f64) {
    let mut rng = Rng(0xC0FFEE ^ ((k as u64) << 32) ^ n as u64);
    (rng.range(-2.0, 8.0), rng.range(0.035, 0.085))
}

/// Step instance `k` for `n` steps; every output after every step, as bits.
unsafe fn run(c: fmi2Component, k: usize, n: usize, start: Option<&Barrier>) -> Vec<u64> {
    let (v, x) = inputs(k, 0);
    initialise(c, Some(1e-6), &[], v, x);
    if let Some(b) = start {
        b.wait();
    }
    let mut bits = Vec::with_capacity(n * 5);
    let mut t = 0.0;
    for i in 0..n {
        let (v, x) = inputs(k, i);
        set_inputs(c, v, x);
        assert_eq!(fmi2DoStep(c, t, H, 1), fmi2OK, "instance {k} step {i}");
        t += H;
        bits.extend(outputs(c).iter().map(|y| y.to_bits()));
    }
    bits
}

#[test]
fn eight_threads_match_serial_bit_for_bit() {
    let seconds: f64 = env_or("JETPIPE_THREADS_SECONDS", 1.0);
    let n = (seconds / H).round() as usize;
    const K: usize = 8;
    let sinks: Vec<Box<Sink>> = (0..K).map(|_| Box::new(Sink::default())).collect();

    let t0 = Instant::now();
    let serial: Vec<Vec<u64>> = (0..K)
        .map(|k| unsafe {
            let c = instantiate(&sinks[k], &format!("serial{k}"));
            let r = run(c, k, n, None);
            fmi2FreeInstance(c);
            r
        })
        .collect();
    let t_serial = t0.elapsed().as_secs_f64();

    // all 8 instances alive at once, each stepped from its own thread
    let comps: Vec<usize> = (0..K)
        .map(|k| unsafe { instantiate(&sinks[k], &format!("thread{k}")) as usize })
        .collect();
    let barrier = Barrier::new(K);
    let t0 = Instant::now();
    let threaded: Vec<Vec<u64>> = std::thread::scope(|s| {
        let handles: Vec<_> = comps
            .iter()
            .enumerate()
            .map(|(k, &c)| {
                let b = &barrier;
                s.spawn(move || unsafe { run(c as fmi2Component, k, n, Some(b)) })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("thread panicked"))
            .collect()
    });
    let t_threads = t0.elapsed().as_secs_f64();
    for &c in &comps {
        free(c as fmi2Component);
    }

    // and serially once more: determinism of the same inputs
    let again: Vec<Vec<u64>> = (0..K)
        .map(|k| unsafe {
            let c = instantiate(&sinks[k], &format!("again{k}"));
            let r = run(c, k, n, None);
            fmi2FreeInstance(c);
            r
        })
        .collect();
    println!(
        "8 instances x {n} steps of {H} s: serial {t_serial:.2} s, 8 threads {t_threads:.2} s; {} outputs compared bit for bit",
        K * n * 5 * 2
    );
    for k in 0..K {
        assert_eq!(serial[k], again[k], "instance {k}: two serial runs differ");
        assert_eq!(
            serial[k], threaded[k],
            "instance {k}: threaded run differs from the serial one"
        );
    }
    for k in 1..K {
        assert_ne!(
            serial[0], serial[k],
            "instances 0 and {k} got the same results: inputs not distinct"
        );
    }
    for s in &sinks {
        assert!(
            s.since(0).iter().all(|m| m.status < fmi2Error),
            "errors logged: {:?}",
            s.since(0)
        );
    }
}

unsafe fn serialize(c: fmi2Component) -> Vec<u8> {
    let mut st: fmi2FMUstate = null_mut();
    assert_eq!(fmi2GetFMUstate(c, &mut st), fmi2OK);
    let mut size = 0;
    assert_eq!(fmi2SerializedFMUstateSize(c, st, &mut size), fmi2OK);
    let mut buf = vec![0 as fmi2Byte; size];
    assert_eq!(fmi2SerializeFMUstate(c, st, buf.as_mut_ptr(), size), fmi2OK);
    assert_eq!(fmi2FreeFMUstate(c, &mut st), fmi2OK);
    buf.iter().map(|&b| b as u8).collect()
}

/// Deserialize and set; the status and the messages logged meanwhile.
unsafe fn restore(c: fmi2Component, sink: &Sink, bytes: &[u8]) -> (fmi2Status, Vec<String>) {
    let m = sink.len();
    let mut st: fmi2FMUstate = null_mut();
    let p = if bytes.is_empty() {
        std::ptr::null()
    } else {
        bytes.as_ptr() as *const fmi2Byte
    };
    let mut s = fmi2DeSerializeFMUstate(c, p, bytes.len(), &mut st);
    if s == fmi2OK {
        s = fmi2SetFMUstate(c, st);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), fmi2OK);
    }
    (s, sink.since(m).into_iter().map(|l| l.message).collect())
}

#[test]
fn serialized_state_continues_exactly_and_bad_states_are_rejected() {
    unsafe {
        let sa = Sink::default();
        let a = instantiate(&sa, "a");
        initialise(a, Some(1e-6), &[], 1.0, 0.05);
        let mut t = 0.0;
        for i in 0..50 {
            let (v, x) = inputs(3, i);
            set_inputs(a, v, x);
            assert_eq!(fmi2DoStep(a, t, H, 1), fmi2OK);
            t += H;
        }
        let blob = serialize(a);

        // continue in a fresh instance from the bytes alone
        let sb = Sink::default();
        let b = instantiate(&sb, "b");
        assert_eq!(restore(b, &sb, &blob).0, fmi2OK);
        let mut t_b = t;
        for i in 50..150 {
            let (v, x) = inputs(3, i);
            for (c, tt) in [(a, &mut t), (b, &mut t_b)] {
                set_inputs(c, v, x);
                assert_eq!(fmi2DoStep(c, *tt, H, 1), fmi2OK);
                *tt += H;
            }
            let (ya, yb) = (outputs(a), outputs(b));
            assert_eq!(
                ya.map(f64::to_bits),
                yb.map(f64::to_bits),
                "restored instance differs at step {i}"
            );
        }

        // rejections: b must be unchanged by each
        let reference = serialize(b);
        let mut rejected = 0;
        let check = |what: &str, bytes: &[u8], needle: &str, rejected: &mut usize| {
            let (s, msgs) = restore(b, &sb, bytes);
            assert_eq!(s, fmi2Error, "{what} accepted");
            assert!(
                msgs.iter().any(|m| m.to_lowercase().contains(needle)),
                "{what}: no message mentioning {needle:?}: {msgs:?}"
            );
            assert_eq!(serialize(b), reference, "{what}: instance changed");
            *rejected += 1;
        };
        // another model version: rewrite the version string inside the model bytes
        let other = other_model_version(&blob, "0.0.9");
        check("state of model version 0.0.9", &other, "version", &mut rejected);
        let other = other_model_version(&blob, "99.1.0-beta");
        check("state of model version 99.1.0-beta", &other, "version", &mut rejected);
        // every single-byte corruption (flip all bits, and +1) and every truncation
        for i in 0..blob.len() {
            let mut bad = blob.clone();
            bad[i] ^= 0xFF;
            check(&format!("byte {i} inverted"), &bad, "", &mut rejected);
            bad[i] = blob[i].wrapping_add(1);
            check(&format!("byte {i} + 1"), &bad, "", &mut rejected);
        }
        for n in 0..blob.len() {
            check(&format!("truncated to {n} bytes"), &blob[..n], "", &mut rejected);
        }
        let mut longer = blob.clone();
        longer.extend_from_slice(&[0, 0, 0, 0]);
        check("4 bytes appended", &longer, "trailing", &mut rejected);
        let mut rng = Rng(42);
        for _ in 0..200 {
            let junk: Vec<u8> = (0..rng.below(2 * blob.len())).map(|_| rng.next_u64() as u8).collect();
            check("random bytes", &junk, "", &mut rejected);
        }
        println!(
            "serialized state: {} bytes; continued bit-identically for 100 steps in another instance; {rejected} bad byte strings rejected (other versions, every byte corrupted, every truncation, random)",
            blob.len()
        );
        fmi2FreeInstance(a);
        fmi2FreeInstance(b);
    }
}

/// The blob with the model-version string in the model bytes replaced; counts and the
/// layer's CRC fixed, so only the model's version check can reject it.
fn other_model_version(blob: &[u8], version: &str) -> Vec<u8> {
    let g = u32::from_le_bytes(blob[12..16].try_into().unwrap()) as usize;
    let at = 16 + g + 1;
    let n = u64::from_le_bytes(blob[at..at + 8].try_into().unwrap()) as usize;
    let model = &blob[at + 8..at + 8 + n];
    let vlen = u32::from_le_bytes(model[24..28].try_into().unwrap()) as usize;
    let mut m = model[..24].to_vec();
    m.extend_from_slice(&(version.len() as u32).to_le_bytes());
    m.extend_from_slice(version.as_bytes());
    m.extend_from_slice(&model[28 + vlen..]);
    let mut b = blob[..at].to_vec();
    b.extend_from_slice(&(m.len() as u64).to_le_bytes());
    b.extend_from_slice(&m);
    let crc = crc32(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    b
}

#[test]
fn state_restore_in_every_legal_state_keeps_inputs_valid() {
    // restoring a state and stepping it twice gives the same bits (the state is not consumed)
    unsafe {
        let s = Sink::default();
        let c = instantiate(&s, "twice");
        initialise(c, Some(1e-6), &[], 4.0, 0.06);
        assert_eq!(fmi2DoStep(c, 0.0, 0.05, 1), fmi2OK);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut st), fmi2OK);
        let mut runs = Vec::new();
        for _ in 0..3 {
            assert_eq!(fmi2SetFMUstate(c, st), fmi2OK);
            set_inputs(c, 6.0, 0.07);
            assert_eq!(fmi2DoStep(c, 0.05, 0.05, 1), fmi2OK);
            runs.push(outputs(c).map(f64::to_bits));
        }
        assert!(runs.windows(2).all(|w| w[0] == w[1]));
        let (_, v) = get_reals(c, &[vr::V_DA]);
        assert_eq!(v[0], 6.0);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), fmi2OK);
        fmi2FreeInstance(c);
    }
}
