//! The FMU-state calls (get, set, free, serialize), generic over the model and over the
//! version's table of functions ([`Call`]): FMI 2.0's `fmi2GetFMUstate` ... and FMI 3.0's
//! `fmi3GetFMUState` ... are the same code. An FMU state records the version and the interface
//! of the instance it was taken from, and only such an instance takes it back.
//!
//! # Safety
//! All functions are `unsafe`: the pointers must satisfy the FMI standard.

use super::api::{guarded, in_slice};
use super::fmu_state::Snapshot;
use super::instance::Instance;
use super::model::CoSimModel;
use super::state::{Call, Function, Version};
use super::types::*;

/// Store `snap` into `*slot`: reuse the live snapshot `*slot` points to, or allocate a
/// new one when `*slot` is NULL.
unsafe fn store_snapshot<M: CoSimModel>(
    inst: &mut Instance<M>,
    fname: &str,
    slot: *mut fmi2FMUstate,
    snap: Snapshot,
) -> fmi2Status {
    let old = *slot;
    if old.is_null() {
        *slot = snap.into_raw();
        fmi2OK
    } else if Snapshot::is_live(old) {
        *(old as *mut Snapshot) = snap;
        fmi2OK
    } else {
        inst.error(format!(
            "{fname}: *FMUstate is neither NULL nor an FMU state of this FMU"
        ))
    }
}

/// The live snapshot behind `s` made for model `M`, or an error message.
unsafe fn snapshot_ref<'a, M: CoSimModel>(fname: &str, s: fmi2FMUstate) -> Result<&'a Snapshot, String> {
    if s.is_null() {
        return Err(format!("{fname}: FMUstate is NULL"));
    }
    if !Snapshot::is_live(s) {
        return Err(format!("{fname}: FMUstate is not a live FMU state (freed or foreign)"));
    }
    let snap = &*(s as *const Snapshot);
    if snap.guid != M::info().guid() {
        return Err(format!(
            "{fname}: FMUstate belongs to another FMU: GUID mismatch: expected {}, got {}",
            M::info().guid(),
            snap.guid
        ));
    }
    Ok(snap)
}

/// `fmi2GetFMUstate`: a boxed snapshot of the layer state and `CoSimModel::serialize`.
///
/// # Safety
/// `state` must point to NULL or to an FMU state returned earlier.
pub unsafe fn get_fmu_state_as<M: CoSimModel, K: Call>(
    c: fmi2Component,
    call: K,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    guarded::<M, K>(c, call, |inst| {
        let fname = call.name();
        if state.is_null() {
            return inst.error(format!("{fname}: FMUstate is NULL"));
        }
        let snap = Snapshot::new::<M>(inst.state, inst.model.serialize())
            .of_interface(inst.interface)
            .of_version(inst.version);
        store_snapshot(inst, fname, state, snap)
    })
}

/// `fmi2SetFMUstate`: `CoSimModel::deserialize` and the stored layer state.
///
/// # Safety
/// `state` must be an FMU state returned by this FMU.
pub unsafe fn set_fmu_state_as<M: CoSimModel, K: Call>(c: fmi2Component, call: K, state: fmi2FMUstate) -> fmi2Status {
    guarded::<M, K>(c, call, |inst| {
        let fname = call.name();
        let snap = match snapshot_ref::<M>(fname, state) {
            Ok(s) => s,
            Err(m) => return inst.error(m),
        };
        if snap.interface != inst.interface || snap.version != inst.version {
            let of = |v: Version| {
                if snap.version == inst.version {
                    String::new()
                } else {
                    format!(" of {}", v.name())
                }
            };
            return inst.error(format!(
                "{fname}: the FMU state was taken from a {} instance{} (state {}); this instance is for {}{}",
                snap.interface.name(),
                of(snap.version),
                snap.state.name_in(snap.version),
                inst.interface.name(),
                of(inst.version)
            ));
        }
        match inst.model.deserialize(&snap.model_bytes) {
            Ok(()) => {
                inst.state = snap.state;
                inst.last_successful_time = None;
                fmi2OK
            }
            Err(m) => inst.error(format!("{fname}: {m}")),
        }
    })
}

/// `fmi2FreeFMUstate`: frees `*state` and sets it to NULL; NULL or `*state == NULL` is a
/// no-op.
///
/// # Safety
/// `state` must be NULL or point to NULL or to an FMU state returned by this FMU.
pub unsafe fn free_fmu_state_as<M: CoSimModel, K: Call>(
    c: fmi2Component,
    call: K,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    guarded::<M, K>(c, call, |inst| {
        let fname = call.name();
        if state.is_null() || (*state).is_null() {
            return fmi2OK;
        }
        if let Err(m) = snapshot_ref::<M>(fname, *state) {
            return inst.error(m);
        }
        Snapshot::free_raw(*state);
        *state = std::ptr::null_mut();
        fmi2OK
    })
}

/// # Safety
/// `size` must be writable.
pub unsafe fn serialized_fmu_state_size_as<M: CoSimModel, K: Call>(
    c: fmi2Component,
    call: K,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    guarded::<M, K>(c, call, |inst| {
        let fname = call.name();
        if size.is_null() {
            return inst.error(format!("{fname}: size is NULL"));
        }
        match snapshot_ref::<M>(fname, state) {
            Ok(snap) => {
                *size = snap.to_bytes().len();
                fmi2OK
            }
            Err(m) => inst.error(m),
        }
    })
}

/// `fmi2SerializeFMUstate`: `size` must equal what `fmi2SerializedFMUstateSize` returned.
///
/// # Safety
/// `bytes` must hold `size` bytes.
pub unsafe fn serialize_fmu_state_as<M: CoSimModel, K: Call>(
    c: fmi2Component,
    call: K,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    guarded::<M, K>(c, call, |inst| {
        let fname = call.name();
        let data = match snapshot_ref::<M>(fname, state) {
            Ok(snap) => snap.to_bytes(),
            Err(m) => return inst.error(m),
        };
        if size != data.len() {
            return inst.error(format!(
                "{fname}: size = {size} but the serialized FMU state has {} bytes (see the serialized size function)",
                data.len()
            ));
        }
        if bytes.is_null() {
            return inst.error(format!("{fname}: serializedState is NULL"));
        }
        std::ptr::copy_nonoverlapping(data.as_ptr(), bytes as *mut u8, size);
        fmi2OK
    })
}

/// `fmi2DeSerializeFMUstate`: parse and check the bytes (see [`crate::fmu_state`]).
///
/// # Safety
/// `bytes` must hold `size` bytes; `state` must point to NULL or to an FMU state.
pub unsafe fn deserialize_fmu_state_as<M: CoSimModel, K: Call>(
    c: fmi2Component,
    call: K,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    guarded::<M, K>(c, call, |inst| {
        let fname = call.name();
        if state.is_null() {
            return inst.error(format!("{fname}: FMUstate is NULL"));
        }
        let data = match in_slice(inst, fname, "serializedState", bytes as *const u8, size) {
            Ok(s) => s,
            Err(s) => return s,
        };
        match Snapshot::from_bytes::<M>(data) {
            Ok(snap) => store_snapshot(inst, fname, state, snap),
            Err(m) => inst.error(format!("{fname}: {m}")),
        }
    })
}

/// [`get_fmu_state_as`] for FMI 2.0.
///
/// # Safety
/// See [`get_fmu_state_as`].
pub unsafe fn get_fmu_state<M: CoSimModel>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    get_fmu_state_as::<M, _>(c, Function::GetFMUstate, state)
}

/// [`set_fmu_state_as`] for FMI 2.0.
///
/// # Safety
/// See [`set_fmu_state_as`].
pub unsafe fn set_fmu_state<M: CoSimModel>(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    set_fmu_state_as::<M, _>(c, Function::SetFMUstate, state)
}

/// [`free_fmu_state_as`] for FMI 2.0.
///
/// # Safety
/// See [`free_fmu_state_as`].
pub unsafe fn free_fmu_state<M: CoSimModel>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    free_fmu_state_as::<M, _>(c, Function::FreeFMUstate, state)
}

/// [`serialized_fmu_state_size_as`] for FMI 2.0.
///
/// # Safety
/// See [`serialized_fmu_state_size_as`].
pub unsafe fn serialized_fmu_state_size<M: CoSimModel>(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    serialized_fmu_state_size_as::<M, _>(c, Function::SerializedFMUstateSize, state, size)
}

/// [`serialize_fmu_state_as`] for FMI 2.0.
///
/// # Safety
/// See [`serialize_fmu_state_as`].
pub unsafe fn serialize_fmu_state<M: CoSimModel>(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    serialize_fmu_state_as::<M, _>(c, Function::SerializeFMUstate, state, bytes, size)
}

/// [`deserialize_fmu_state_as`] for FMI 2.0.
///
/// # Safety
/// See [`deserialize_fmu_state_as`].
pub unsafe fn deserialize_fmu_state<M: CoSimModel>(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    deserialize_fmu_state_as::<M, _>(c, Function::DeSerializeFMUstate, bytes, size, state)
}
