//! The byte format of a model's state, what a [`crate::model::CoSimModel`]'s `serialize`
//! writes and `deserialize` reads (the layer wraps it in its own checksummed frame, see
//! [`crate::fmu_state`]). Every model of this workspace writes its state with it.
//!
//! | bytes | what |
//! |---|---|
//! | `magic.len()` | the magic string naming the model ([`StateFormat::magic`]) |
//! | 4 | the model's state format version (`u32`) |
//! | 4 + n | the crate version that wrote it: its length (`u32`, at most 64), its UTF-8 bytes |
//! | … | the model's values, as the model writes them |
//!
//! Numbers are little-endian: `u32`, `u64`, `f64` (IEEE 754 bits, so every value, NaN and
//! infinities included, comes back bit for bit). A counted array is its length (`u32`) then
//! its items; a string is a counted array of UTF-8 bytes. There are no pointers, so the bytes
//! are valid in another process.
//!
//! A state is only read back by the same model at the same format and crate versions:
//! anything else is refused, as are truncated bytes, counts that the remaining bytes cannot
//! hold (so a forged count allocates nothing) and bytes left over after the model's values,
//! each with a message that says which.

/// What a model's state image starts with, and what [`ByteReader`] checks it against.
pub struct StateFormat {
    pub magic: &'static [u8],
    pub version: u32,
    pub crate_version: &'static str,
    /// The model's name, for the message on foreign bytes.
    pub model: &'static str,
}

impl StateFormat {
    pub fn writer(&self) -> ByteWriter {
        ByteWriter::new(self.magic, self.version, self.crate_version)
    }

    pub fn reader<'a>(&self, bytes: &'a [u8]) -> Result<ByteReader<'a>, String> {
        ByteReader::open(bytes, self.magic, self.version, self.crate_version, self.model)
    }
}

/// A model's [`StateFormat`], with the calling crate's version (hence a macro: `env!` in a
/// function here would give this crate's).
#[macro_export]
macro_rules! state_format {
    (magic: $magic:expr, version: $version:expr, model: $model:expr $(,)?) => {
        $crate::state_bytes::StateFormat {
            magic: $magic,
            version: $version,
            crate_version: env!("CARGO_PKG_VERSION"),
            model: $model,
        }
    };
}

/// The longest crate version string a reader takes: far beyond any semantic version, short
/// enough that a corrupted length is caught before the bytes are compared.
const MAX_VERSION_LEN: usize = 64;

#[derive(Default)]
pub struct ByteWriter(pub Vec<u8>);

impl ByteWriter {
    /// Starts the image with the header that [`ByteReader::open`] checks.
    pub fn new(magic: &[u8], format_version: u32, crate_version: &str) -> Self {
        let mut w = Self::default();
        w.0.extend_from_slice(magic);
        w.u32(format_version);
        w.string(crate_version);
        w
    }
    pub fn into_bytes(self) -> Vec<u8> {
        self.0
    }
    pub fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    /// 0 or 1, as a `u32`.
    pub fn bool(&mut self, v: bool) {
        self.u32(u32::from(v));
    }
    pub fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    /// Its length, then the numbers.
    pub fn f64s(&mut self, vs: &[f64]) {
        self.u32(vs.len() as u32);
        for &v in vs {
            self.f64(v);
        }
    }
    /// Its length in bytes, then its UTF-8 bytes.
    pub fn string(&mut self, s: &str) {
        self.u32(s.len() as u32);
        self.0.extend_from_slice(s.as_bytes());
    }
    /// A flag (0 or 1), then the numbers if there are any: the state a model has from
    /// initialisation on.
    pub fn optional_f64s<const N: usize>(&mut self, vs: Option<[f64; N]>) {
        match vs {
            None => self.u32(0),
            Some(vs) => {
                self.u32(1);
                self.f64s(&vs);
            }
        }
    }
}

pub struct ByteReader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> ByteReader<'a> {
    /// Checks the header written by [`ByteWriter::new`]: the magic, then the format version,
    /// then the crate version.
    pub fn open(
        bytes: &'a [u8],
        magic: &[u8],
        format_version: u32,
        crate_version: &str,
        model: &str,
    ) -> Result<Self, String> {
        let mut r = Self { bytes, at: 0 };
        if r.take(magic.len()).ok() != Some(magic) {
            return Err(format!("the state was not written by the {model} model"));
        }
        let format = r.u32()?;
        if format != format_version {
            return Err(format!(
                "state format version {format} is not supported (this model reads version {format_version})"
            ));
        }
        let version = r.string(MAX_VERSION_LEN, "version string")?;
        if version != crate_version {
            return Err(format!(
                "the state was written by model version {version}; this is version {crate_version}"
            ));
        }
        Ok(r)
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| {
                format!(
                    "the state is truncated: {} bytes, needed more than {}",
                    self.bytes.len(),
                    self.at
                )
            })?;
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }
    fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }
    pub fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    pub fn u64(&mut self) -> Result<u64, String> {
        let mut a = [0u8; 8];
        a.copy_from_slice(self.take(8)?);
        Ok(u64::from_le_bytes(a))
    }
    /// What [`ByteWriter::bool`] wrote; any other number is refused, `what` names it.
    pub fn bool(&mut self, what: &str) -> Result<bool, String> {
        match self.u32()? {
            0 => Ok(false),
            1 => Ok(true),
            other => Err(format!("the state's {what} flag is {other}, not 0 or 1")),
        }
    }
    pub fn f64(&mut self) -> Result<f64, String> {
        let mut a = [0u8; 8];
        a.copy_from_slice(self.take(8)?);
        Ok(f64::from_le_bytes(a))
    }
    /// A count of items of `item_bytes` bytes each that follow, refused when the rest of
    /// the state cannot hold them (so a forged count allocates nothing).
    pub fn count(&mut self, item_bytes: usize, what: &str) -> Result<usize, String> {
        let count = self.u32()? as usize;
        if count.saturating_mul(item_bytes) > self.remaining() {
            return Err(format!(
                "the state is truncated (or its count corrupted): it claims {count} {what}, more than its remaining {} bytes hold",
                self.remaining()
            ));
        }
        Ok(count)
    }
    /// What [`ByteWriter::f64s`] wrote.
    pub fn f64s(&mut self) -> Result<Vec<f64>, String> {
        self.f64s_at_most(usize::MAX, "numbers")
    }
    /// What [`ByteWriter::f64s`] wrote, refused beyond `max` numbers (or beyond what the
    /// rest of the state holds); `what` names them in the messages.
    pub fn f64s_at_most(&mut self, max: usize, what: &str) -> Result<Vec<f64>, String> {
        let n = self.count(8, what)?;
        if n > max {
            return Err(format!("the state claims {n} {what}, more than the {max} it can have"));
        }
        (0..n).map(|_| self.f64()).collect()
    }
    /// What [`ByteWriter::string`] wrote, refused beyond `max_len` bytes or when not UTF-8.
    pub fn string(&mut self, max_len: usize, what: &str) -> Result<String, String> {
        let n = self.u32()? as usize;
        if n > max_len {
            return Err(format!("the state's {what} is implausibly long ({n} bytes)"));
        }
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| format!("the state's {what} is not UTF-8"))
    }
    /// What [`ByteWriter::optional_f64s`] wrote: exactly `N` finite numbers if the flag is 1
    /// (any other flag reads as none). `what` names them in the message on a wrong count.
    pub fn optional_f64s<const N: usize>(&mut self, what: &str) -> Result<Option<[f64; N]>, String> {
        if self.u32()? != 1 {
            return Ok(None);
        }
        let v = self.f64s()?;
        let vs: [f64; N] = v[..]
            .try_into()
            .map_err(|_| format!("the state holds {} {what} values, expected {N}", v.len()))?;
        if !vs.iter().all(|x| x.is_finite()) {
            return Err("the state holds non-finite values".to_string());
        }
        Ok(Some(vs))
    }
    /// Every byte must have been read.
    pub fn finish(self) -> Result<(), String> {
        if self.at != self.bytes.len() {
            return Err(format!(
                "{} unexpected trailing bytes after the state",
                self.bytes.len() - self.at
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FORMAT: StateFormat = StateFormat {
        magic: b"M",
        version: 1,
        crate_version: "0.1.0",
        model: "M",
    };

    #[test]
    fn every_kind_of_value_round_trips_bit_for_bit() {
        let mut w = FORMAT.writer();
        w.u32(7);
        w.u64(u64::MAX - 1);
        w.bool(true);
        w.f64(-0.0);
        w.f64(f64::NEG_INFINITY);
        w.f64s(&[1.0, f64::NAN]);
        w.string("ünï");
        let bytes = w.into_bytes();
        let mut r = FORMAT.reader(&bytes).unwrap();
        assert_eq!(r.u32().unwrap(), 7);
        assert_eq!(r.u64().unwrap(), u64::MAX - 1);
        assert!(r.bool("b").unwrap());
        assert_eq!(r.f64().unwrap().to_bits(), (-0.0f64).to_bits());
        assert_eq!(r.f64().unwrap(), f64::NEG_INFINITY);
        let v = r.f64s_at_most(2, "x").unwrap();
        assert_eq!((v[0], v[1].to_bits()), (1.0, f64::NAN.to_bits()));
        assert_eq!(r.string(8, "s").unwrap(), "ünï");
        r.finish().unwrap();
    }

    #[test]
    fn headers_of_other_models_formats_and_versions_are_refused_with_their_reason() {
        let bytes = FORMAT.writer().into_bytes();
        let open = |magic: &[u8], version: u32, crate_version: &str| {
            ByteReader::open(&bytes, magic, version, crate_version, "Other").err()
        };
        assert!(open(b"X", 1, "0.1.0")
            .unwrap()
            .contains("not written by the Other model"));
        assert!(open(b"M", 2, "0.1.0")
            .unwrap()
            .contains("format version 1 is not supported"));
        assert!(open(b"M", 1, "0.2.0").unwrap().contains("model version 0.1.0"));
        assert!(open(b"M", 1, "0.1.0").is_none());
        let mut long = b"M".to_vec();
        long.extend_from_slice(&1u32.to_le_bytes());
        long.extend_from_slice(&1000u32.to_le_bytes());
        assert!(FORMAT.reader(&long).err().unwrap().contains("implausibly long"));
    }

    #[test]
    fn truncated_counted_and_trailing_bytes_are_refused_with_their_reason() {
        let mut w = FORMAT.writer();
        w.f64s(&[1.0, 2.0]);
        w.f64(3.0);
        w.u32(2);
        let bytes = w.into_bytes();
        let mut r = FORMAT.reader(&bytes[..bytes.len() - 7]).unwrap();
        r.f64s().unwrap();
        assert!(r.f64().unwrap_err().contains("truncated"));
        let mut r = FORMAT.reader(&bytes).unwrap();
        assert!(r
            .f64s_at_most(1, "samples")
            .unwrap_err()
            .contains("2 samples, more than the 1 it can have"));
        let mut r = FORMAT.reader(&bytes).unwrap();
        r.f64s().unwrap();
        r.f64().unwrap();
        assert!(r.bool("on").unwrap_err().contains("on flag is 2"));
        // A count the rest cannot hold is refused before anything is allocated.
        let mut forged = FORMAT.writer();
        forged.u32(u32::MAX);
        let forged = forged.into_bytes();
        let mut r = FORMAT.reader(&forged).unwrap();
        assert!(r.f64s().unwrap_err().contains("more than its remaining 0 bytes hold"));
        let mut longer = bytes.clone();
        longer.push(0);
        let mut r = FORMAT.reader(&longer).unwrap();
        r.f64s().unwrap();
        r.f64().unwrap();
        r.u32().unwrap();
        assert!(r.finish().unwrap_err().contains("1 unexpected trailing bytes"));
    }

    #[test]
    fn optional_numbers_round_trip_and_are_checked() {
        let mut w = FORMAT.writer();
        w.optional_f64s::<2>(None);
        w.optional_f64s(Some([1.0, 2.0]));
        w.optional_f64s(Some([f64::NAN]));
        let bytes = w.0;
        let mut r = FORMAT.reader(&bytes).unwrap();
        assert_eq!(r.optional_f64s::<2>("x").unwrap(), None);
        assert!(r
            .optional_f64s::<3>("x")
            .unwrap_err()
            .contains("2 x values, expected 3"));
        assert!(r.optional_f64s::<1>("x").unwrap_err().contains("non-finite"));
        r.finish().unwrap();
    }
}
