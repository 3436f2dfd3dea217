//! FMU states (`fmi2FMUstate`) and their versioned, checksummed byte format.
//!
//! Byte format, version 1 (all integers little-endian, no pointers):
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `b"FMI2STAT"` |
//! | 4 | format version (`u32`, = 1) |
//! | 4 | GUID length `g` (`u32`) |
//! | g | GUID (UTF-8) of the model that wrote it |
//! | 1 | layer state (see [`State::code`]), plus [`MODEL_EXCHANGE_BIT`] for an instance of Model Exchange and [`FMI3_BIT`] for an instance of FMI 3.0 |
//! | 8 | model byte count `n` (`u64`) |
//! | n | `CoSimModel::serialize()` |
//! | 4 | CRC-32 (IEEE, as zlib) of everything before it |

use super::instance::{is_registered_handle, register_handle, unregister_handle, HandleKind};
use super::model::CoSimModel;
use super::state::{Interface, State, Version};

/// Set in the layer-state byte of an FMU state taken from a Model Exchange instance (a
/// Co-Simulation instance's bytes are those of the layer before Model Exchange).
pub const MODEL_EXCHANGE_BIT: u8 = 0x80;

/// Set in the layer-state byte of an FMU state taken from an FMI 3.0 instance (the FMI 2.0
/// bytes are those of the layer before FMI 3.0).
pub const FMI3_BIT: u8 = 0x40;

pub const STATE_MAGIC: &[u8; 8] = b"FMI2STAT";
pub const FORMAT_VERSION: u32 = 1;
/// Marks a live [`Snapshot`] in memory; cleared when it is freed.
pub const SNAPSHOT_MAGIC: u64 = 0x4649_4D32_534E_4150; // "FIM2SNAP"

/// What an `fmi2FMUstate` points to.
#[repr(C)]
pub struct Snapshot {
    pub(crate) magic: u64,
    /// GUID of the model type that made it (rejects states of another FMU in-process).
    pub guid: &'static str,
    pub state: State,
    /// The interface of the instance it was taken from.
    pub interface: Interface,
    /// The FMI version of the instance it was taken from.
    pub version: Version,
    pub model_bytes: Vec<u8>,
}

impl Snapshot {
    pub fn new<M: CoSimModel>(state: State, model_bytes: Vec<u8>) -> Self {
        Snapshot {
            magic: SNAPSHOT_MAGIC,
            guid: M::info().guid(),
            state,
            interface: Interface::CoSimulation,
            version: Version::Fmi2,
            model_bytes,
        }
    }

    /// The snapshot, as taken from an instance of `interface`.
    pub fn of_interface(mut self, interface: Interface) -> Self {
        self.interface = interface;
        self
    }

    /// The snapshot, as taken from an instance of `version`.
    pub fn of_version(mut self, version: Version) -> Self {
        self.version = version;
        self
    }

    /// Whether `p` is a live FMU state: registered when it was boxed and not yet freed
    /// (checked without reading `*p`), with its magic number intact.
    ///
    /// # Safety
    /// None beyond the FMI contract (see `Instance::is_live`).
    pub unsafe fn is_live(p: *const std::ffi::c_void) -> bool {
        is_registered_handle(p, HandleKind::Snapshot) && std::ptr::read_volatile(p as *const u64) == SNAPSHOT_MAGIC
    }

    /// Box the snapshot and register it: the `fmi2FMUstate` handed to the importer.
    pub fn into_raw(self) -> *mut std::ffi::c_void {
        let p = Box::into_raw(Box::new(self)) as *mut std::ffi::c_void;
        register_handle(p, HandleKind::Snapshot);
        p
    }

    /// Free a snapshot made by [`Snapshot::into_raw`].
    ///
    /// # Safety
    /// `p` must be live ([`Snapshot::is_live`]) and not used afterwards.
    pub unsafe fn free_raw(p: *mut std::ffi::c_void) {
        unregister_handle(p, HandleKind::Snapshot);
        let mut snap = Box::from_raw(p as *mut Snapshot);
        snap.kill();
        drop(snap);
    }

    pub fn kill(&mut self) {
        unsafe { std::ptr::write_volatile(&mut self.magic, 0) };
    }

    /// The byte image described in the module documentation.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(37 + self.guid.len() + self.model_bytes.len());
        out.extend_from_slice(STATE_MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(self.guid.len() as u32).to_le_bytes());
        out.extend_from_slice(self.guid.as_bytes());
        let interface_bit = match self.interface {
            Interface::CoSimulation => 0,
            Interface::ModelExchange => MODEL_EXCHANGE_BIT,
        };
        let version_bit = match self.version {
            Version::Fmi2 => 0,
            Version::Fmi3 => FMI3_BIT,
        };
        out.push(self.state.code() | interface_bit | version_bit);
        out.extend_from_slice(&(self.model_bytes.len() as u64).to_le_bytes());
        out.extend_from_slice(&self.model_bytes);
        let crc = crc32(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out
    }

    /// Parse and check a byte image written by [`Snapshot::to_bytes`] for model `M`;
    /// the model bytes are checked by deserializing them into a fresh model.
    /// The error says what is wrong (truncated, magic, version, checksum, GUID, ...).
    pub fn from_bytes<M: CoSimModel>(bytes: &[u8]) -> Result<Snapshot, String> {
        let mut r = Reader { bytes, pos: 0 };
        let magic = r.take(8, "magic")?;
        if magic != STATE_MAGIC {
            return Err(format!(
                "not a serialized FMU state of this layer: wrong magic bytes {magic:02x?} (expected {STATE_MAGIC:02x?})"
            ));
        }
        let version = r.u32("format version")?;
        if version != FORMAT_VERSION {
            return Err(format!(
                "unsupported serialized FMU state format version {version} (this FMU reads version {FORMAT_VERSION})"
            ));
        }
        let guid_len = r.u32("GUID length")? as usize;
        let guid = r.take(guid_len, "GUID")?;
        let code = r.take(1, "layer state")?[0];
        let n = r.u64("model byte count")?;
        let n = usize::try_from(n).map_err(|_| format!("truncated serialized FMU state: model byte count {n}"))?;
        let model_bytes = r.take(n, "model bytes")?.to_vec();
        let body_len = r.pos;
        let stored_crc = r.u32("checksum")?;
        if r.pos != bytes.len() {
            return Err(format!(
                "serialized FMU state has {} trailing bytes after the checksum",
                bytes.len() - r.pos
            ));
        }
        let crc = crc32(&bytes[..body_len]);
        if crc != stored_crc {
            return Err(format!(
                "corrupted serialized FMU state: checksum mismatch (stored {stored_crc:08x}, computed {crc:08x})"
            ));
        }
        let expected = M::info().guid();
        if guid != expected.as_bytes() {
            return Err(format!(
                "serialized FMU state of another FMU: GUID mismatch: expected {expected}, got {}",
                String::from_utf8_lossy(guid)
            ));
        }
        let interface = if code & MODEL_EXCHANGE_BIT != 0 {
            Interface::ModelExchange
        } else {
            Interface::CoSimulation
        };
        let version = if code & FMI3_BIT != 0 {
            Version::Fmi3
        } else {
            Version::Fmi2
        };
        let state = State::from_code(code & !(MODEL_EXCHANGE_BIT | FMI3_BIT))
            .ok_or_else(|| format!("invalid layer state code {code} in serialized FMU state"))?;
        if state == State::Fatal {
            return Err("serialized FMU state is in the fatal state".to_owned());
        }
        if state.interface().map_or(false, |i| i != interface) {
            return Err(format!(
                "invalid layer state code {code} in serialized FMU state: state {} of a {} instance",
                state.name(),
                interface.name()
            ));
        }
        let mut probe = M::instantiate();
        probe
            .deserialize(&model_bytes)
            .map_err(|e| format!("serialized FMU state rejected by the model: {e}"))?;
        Ok(Snapshot::new::<M>(state, model_bytes)
            .of_interface(interface)
            .of_version(version))
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| {
                format!(
                    "truncated serialized FMU state: {} bytes, {what} needs {n} bytes at offset {}",
                    self.bytes.len(),
                    self.pos
                )
            })?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().unwrap()))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().unwrap()))
    }
}

const fn crc_table() -> [u32; 256] {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
            k += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
}
static CRC_TABLE: [u32; 256] = crc_table();

/// CRC-32 (IEEE 802.3, reflected, as zlib's `crc32`).
pub fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c = CRC_TABLE[((c ^ b as u32) & 0xFF) as usize] ^ (c >> 8);
    }
    !c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_known_values() {
        assert_eq!(crc32(b""), 0);
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b"The quick brown fox jumps over the lazy dog"), 0x414F_A339);
    }
}
