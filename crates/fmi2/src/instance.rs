//! One FMU instance: the model plus everything the layer keeps about it, and logging.

use std::collections::BTreeSet;
use std::ffi::{CStr, CString};
use std::os::raw::c_void;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use super::model::{CoSimModel, VarType, Variable};
use super::state::{Interface, State, Version};
use super::types::*;

/// Marks a live [`Instance`]; cleared by `fmi2FreeInstance`.
pub const INSTANCE_MAGIC: u64 = 0x4649_4D32_494E_5354; // "FIM2INST"

/// What a registered address is: kept apart so an FMU state is never taken for an instance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum HandleKind {
    Instance,
    Snapshot,
}

/// Addresses of every live instance and FMU state of this process. A handle is checked
/// here before it is dereferenced, so a NULL, freed (double `fmi2FreeInstance`,
/// `fmi2FreeFMUstate` twice through a copy of the pointer) or foreign pointer is rejected
/// without reading the memory it points to. The lock is held only for the set operation.
/// `None` while no handle is live (and a set cannot be made in a const on Rust 1.63).
static LIVE_HANDLES: Mutex<Option<BTreeSet<(usize, HandleKind)>>> = Mutex::new(None);

fn live_handles() -> std::sync::MutexGuard<'static, Option<BTreeSet<(usize, HandleKind)>>> {
    // a set of integers cannot be left inconsistent by a panic: ignore poisoning
    LIVE_HANDLES.lock().unwrap_or_else(|e| e.into_inner())
}

/// The instance handle last found live in the registry (0: none), so that the calls of one
/// step find their instance without taking the lock. Written only while the registry's lock
/// is held, and cleared there when that handle is unregistered: it never holds the address
/// of a freed instance.
static RECENT_INSTANCE: AtomicUsize = AtomicUsize::new(0);

/// Record `p` as a live handle of this kind.
pub fn register_handle(p: *const c_void, kind: HandleKind) {
    live_handles()
        .get_or_insert_with(BTreeSet::new)
        .insert((p as usize, kind));
}

/// Forget `p`; whether it was registered.
pub fn unregister_handle(p: *const c_void, kind: HandleKind) -> bool {
    let mut set = live_handles();
    let removed = set.as_mut().map_or(false, |s| s.remove(&(p as usize, kind)));
    if kind == HandleKind::Instance {
        // under the lock, before the instance is freed
        let _ = RECENT_INSTANCE.compare_exchange(p as usize, 0, Ordering::AcqRel, Ordering::Acquire);
    }
    if set.as_ref().map_or(false, |s| s.is_empty()) {
        // an emptied BTreeSet keeps its root node: release it, so that no allocation
        // outlives the last handle (and a dlclose'd library leaves no block behind)
        *set = None;
    }
    removed
}

/// Whether `p` is a live handle of this kind (no memory behind `p` is read).
#[inline]
pub fn is_registered_handle(p: *const c_void, kind: HandleKind) -> bool {
    if p.is_null() {
        return false;
    }
    if kind == HandleKind::Instance && RECENT_INSTANCE.load(Ordering::Acquire) == p as usize {
        return true;
    }
    is_in_the_registry(p, kind)
}

/// [`is_registered_handle`] by the registry itself, under its lock.
#[inline(never)]
fn is_in_the_registry(p: *const c_void, kind: HandleKind) -> bool {
    let set = live_handles();
    let live = set.as_ref().map_or(false, |s| s.contains(&(p as usize, kind)));
    if live && kind == HandleKind::Instance {
        RECENT_INSTANCE.store(p as usize, Ordering::Release);
    }
    live
}

/// Log categories the layer itself uses.
pub const CAT_ERROR: &str = "logStatusError";
pub const CAT_FATAL: &str = "logStatusFatal";
pub const CAT_DISCARD: &str = "logStatusDiscard";
pub const CAT_WARNING: &str = "logStatusWarning";
pub const CAT_CALLS: &str = "logCalls";

/// FMI 3.0's `fmi3LogMessageCallback`: not variadic, no instance name (the status is the same
/// `c_int` numbering as `fmi2Status`: OK 0 ... Fatal 4).
pub type LogMessageCallback = Option<
    unsafe extern "C" fn(
        instance_environment: *mut c_void,
        status: std::os::raw::c_int,
        category: *const std::os::raw::c_char,
        message: *const std::os::raw::c_char,
    ),
>;

/// An FMU instance. `fmi2Component` (and `fmi3Instance`) points to one of these (boxed).
///
/// `#[repr(C)]` with `magic` first, so the magic number sits at offset 0 whatever `M`
/// is, and can be checked through a pointer before the instance is otherwise used.
#[repr(C)]
pub struct Instance<M: CoSimModel> {
    magic: u64,
    pub model: M,
    pub instance_name: String,
    instance_name_c: CString,
    pub logger: fmi2CallbackLogger,
    pub component_environment: fmi2ComponentEnvironment,
    /// The logger of an FMI 3.0 instance (`logger` is then `None`).
    pub log_message: LogMessageCallback,
    /// The FMI version whose calls made the instance and may use it.
    pub version: Version,
    /// The last `loggingOn` given to `fmi2Instantiate` or `fmi2SetDebugLogging`.
    pub logging_on: bool,
    /// One flag per entry of `M::info().log_categories`.
    pub categories_enabled: Vec<bool>,
    /// Where the model declares the "logCalls" category in `M::info().log_categories`, found
    /// once: every call asks whether to trace itself.
    calls_category: Option<usize>,
    /// By value reference, the first row of `M::info().variables` with it ([`NO_ROW`]: none),
    /// so that the getters and setters find a variable without a search; empty when the
    /// references are too large for such a table (then [`Instance::variable`] searches).
    variable_rows: Vec<u16>,
    pub state: State,
    /// The interface the instance was made for (`fmi2Instantiate`'s `fmuType`).
    pub interface: Interface,
    /// `last_successful_time` of the last `fmi2DoStep` that returned fmi2Discard (the
    /// model's `time()` is what `fmi2GetRealStatus` reports).
    pub last_successful_time: Option<f64>,
    /// The text of the last message logged with fmi2Error or fmi2Fatal.
    pub last_error: Option<String>,
    /// Every message that passed the filter (status, category, text); only in tests.
    #[cfg(test)]
    pub captured: Vec<(fmi2Status, String, String)>,
}

impl<M: CoSimModel> Instance<M> {
    pub fn new(model: M, instance_name: &str, callbacks: Option<&fmi2CallbackFunctions>, logging_on: bool) -> Self {
        let n = M::info().log_categories.len();
        Instance {
            magic: INSTANCE_MAGIC,
            model,
            instance_name: instance_name.to_owned(),
            instance_name_c: to_cstring(instance_name),
            logger: callbacks.and_then(|c| c.logger),
            component_environment: callbacks.map_or(std::ptr::null_mut(), |c| c.componentEnvironment),
            log_message: None,
            version: Version::Fmi2,
            logging_on,
            categories_enabled: vec![logging_on; n],
            calls_category: M::info().log_categories.iter().position(|(name, _)| *name == CAT_CALLS),
            variable_rows: variable_rows(M::info().variables),
            state: State::Instantiated,
            interface: Interface::CoSimulation,
            last_successful_time: None,
            last_error: None,
            #[cfg(test)]
            captured: Vec::new(),
        }
    }

    /// An instance for FMI 3.0: its logger is `log_message`, called with `environment`.
    pub fn new_fmi3(
        model: M,
        instance_name: &str,
        environment: *mut c_void,
        log_message: LogMessageCallback,
        logging_on: bool,
    ) -> Self {
        let mut instance = Self::new(model, instance_name, None, logging_on);
        instance.component_environment = environment;
        instance.log_message = log_message;
        instance.version = Version::Fmi3;
        instance
    }

    /// The state's name in the instance's version (see [`State::name_in`]).
    pub fn state_name(&self) -> &'static str {
        self.state.name_in(self.version)
    }

    /// The variable with value reference `vr` and type `ty`: what [`crate::api::lookup`]
    /// finds (the first such row), looked up in the table of rows when the first row with
    /// `vr` has that type, searched for otherwise (and for the message when there is none).
    #[inline]
    pub fn variable(&self, fname: &str, vr: u32, ty: VarType) -> Result<&'static Variable, String> {
        match self.tabled_variable(vr, ty) {
            Some(v) => Ok(v),
            None => crate::api::lookup_in::<M>(fname, vr, ty, self.version),
        }
    }

    /// The variable [`Self::variable`] finds when the table of rows has it; `None` when the
    /// table does not (the variable may still exist: then `variable` searches for it).
    #[inline]
    pub fn tabled_variable(&self, vr: u32, ty: VarType) -> Option<&'static Variable> {
        let v = M::info()
            .variables
            .get(usize::from(*self.variable_rows.get(vr as usize)?))?;
        (v.var_type == ty).then_some(v)
    }

    /// Whether `c` is a live instance: registered by `fmi2Instantiate` and not yet freed
    /// (checked in the handle registry, without reading `*c`), with its magic number
    /// intact.
    ///
    /// # Safety
    /// None beyond the FMI contract: a NULL, freed or foreign pointer is answered from the
    /// registry without being dereferenced. The one case that cannot be told apart is a
    /// freed address that the allocator has given to a new instance.
    pub unsafe fn is_live(c: fmi2Component) -> bool {
        is_registered_handle(c, HandleKind::Instance) && std::ptr::read_volatile(c as *const u64) == INSTANCE_MAGIC
    }

    /// Box the instance and register it: the `fmi2Component` handed to the importer.
    pub fn into_component(self) -> fmi2Component {
        let c = Box::into_raw(Box::new(self)) as fmi2Component;
        register_handle(c, HandleKind::Instance);
        c
    }

    /// Clear the magic number (just before the instance is dropped).
    pub fn kill(&mut self) {
        // volatile so the store is not optimised away before the deallocation
        unsafe { std::ptr::write_volatile(&mut self.magic, 0) };
    }

    /// Whether a message with this status and category passes the filter: fmi2Discard,
    /// fmi2Error and fmi2Fatal always pass; others need logging on for their category
    /// (a category the model does not declare follows the global `logging_on`).
    /// Whether calls are traced: the model declares "logCalls" and it is enabled (what
    /// `should_log(fmi2OK, CAT_CALLS)` says for a declared category).
    pub fn logs_calls(&self) -> bool {
        self.calls_category.map_or(false, |i| self.categories_enabled[i])
    }

    pub fn should_log(&self, status: fmi2Status, category: &str) -> bool {
        if status >= fmi2Discard {
            return true;
        }
        match M::info().log_categories.iter().position(|(name, _)| *name == category) {
            Some(i) => self.categories_enabled[i],
            None => self.logging_on,
        }
    }

    /// Log through the importer's logger (if any) after filtering; errors are remembered
    /// in `last_error`.
    pub fn log(&mut self, status: fmi2Status, category: &str, message: &str) {
        if status >= fmi2Error {
            self.last_error = Some(message.to_owned());
        }
        if !self.should_log(status, category) {
            return;
        }
        #[cfg(test)]
        self.captured.push((status, category.to_owned(), message.to_owned()));
        if self.version == Version::Fmi3 {
            // SAFETY: the callback and environment come from the importer's fmi3Instantiate*.
            unsafe { call_log_message(self.log_message, self.component_environment, status, category, message) };
            return;
        }
        // SAFETY: the logger and environment come from the importer's callbacks.
        unsafe {
            call_logger(
                self.logger,
                self.component_environment,
                &self.instance_name_c,
                status,
                category,
                message,
            )
        };
    }

    pub fn log_error(&mut self, message: &str) {
        self.log(fmi2Error, CAT_ERROR, message);
    }

    /// Log an error and return fmi2Error.
    pub fn error(&mut self, message: impl AsRef<str>) -> fmi2Status {
        self.log_error(message.as_ref());
        fmi2Error
    }
}

/// In [`Instance`]'s table of rows: no variable has this value reference.
const NO_ROW: u16 = u16::MAX;

/// Value references up to this one get a row in [`Instance`]'s table (2 bytes each).
const MAX_TABLED_REFERENCE: u32 = 1 << 14;

/// The first row of `variables` for each value reference, or an empty table when a value
/// reference or the number of rows is too large for one.
fn variable_rows(variables: &[Variable]) -> Vec<u16> {
    let largest = variables.iter().map(|v| v.value_reference).max();
    let largest = match largest {
        Some(largest) if largest < MAX_TABLED_REFERENCE && variables.len() < usize::from(NO_ROW) => largest,
        _ => return Vec::new(),
    };
    let mut rows = vec![NO_ROW; largest as usize + 1];
    for (row, v) in variables.iter().enumerate() {
        let slot = &mut rows[v.value_reference as usize];
        if *slot == NO_ROW {
            *slot = row as u16;
        }
    }
    rows
}

/// A `CString` from arbitrary text (interior NULs become U+FFFD).
pub fn to_cstring(s: &str) -> CString {
    CString::new(s.replace('\0', "\u{FFFD}")).expect("no interior NUL left")
}

/// Call an FMI 3.0 importer's `fmi3LogMessageCallback` (the message is passed as text, never
/// as a format).
///
/// # Safety
/// `log_message` and `env` must be what the importer passed to `fmi3Instantiate*`.
pub unsafe fn call_log_message(
    log_message: LogMessageCallback,
    env: *mut c_void,
    status: fmi2Status,
    category: &str,
    message: &str,
) {
    if let Some(log_message) = log_message {
        let category = to_cstring(category);
        let message = to_cstring(message);
        log_message(env, status, category.as_ptr(), message.as_ptr());
    }
}

/// Call an importer's variadic logger as `logger(env, name, status, category, "%s", message)`.
/// The message is always passed as the argument of a `"%s"` format, never as the format.
///
/// # Safety
/// `logger` and `env` must be what the importer passed in `fmi2CallbackFunctions`.
pub unsafe fn call_logger(
    logger: fmi2CallbackLogger,
    env: fmi2ComponentEnvironment,
    instance_name: &CStr,
    status: fmi2Status,
    category: &str,
    message: &str,
) {
    if let Some(logger) = logger {
        let category = to_cstring(category);
        let message = to_cstring(message);
        logger(
            env,
            instance_name.as_ptr(),
            status,
            category.as_ptr(),
            b"%s\0".as_ptr() as *const std::os::raw::c_char,
            message.as_ptr(),
        );
    }
}
