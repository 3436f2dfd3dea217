//! The FMU-state byte format of the three models: a magic string naming the model, a format
//! version, the crate version, then little-endian numbers. No pointers, so the bytes are
//! valid in another process; every read checks the length so corrupted bytes give a message.

/// What a model's state image starts with, and what `ByteReader` checks it against.
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

/// A model's `StateFormat`, with the calling crate's version (hence a macro).
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

#[derive(Default)]
pub struct ByteWriter(pub Vec<u8>);

impl ByteWriter {
    /// Starts the image with the header that `ByteReader::open` checks.
    pub fn new(magic: &[u8], format_version: u32, crate_version: &str) -> Self {
        let mut w = Self::default();
        w.0.extend_from_slice(magic);
        w.u32(format_version);
        w.u32(crate_version.len() as u32);
        w.0.extend_from_slice(crate_version.as_bytes());
        w
    }
    pub fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64s(&mut self, vs: &[f64]) {
        self.u32(vs.len() as u32);
        for &v in vs {
            self.f64(v);
        }
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
    /// Check the header written by `ByteWriter::new`.
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
        let n = r.u32()? as usize;
        if n > 64 {
            return Err("the state's version string is implausibly long".to_string());
        }
        let version = String::from_utf8(r.take(n)?.to_vec()).map_err(|_| "the state's version is not UTF-8")?;
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
            .ok_or_else(|| format!("the state is truncated: {} bytes", self.bytes.len()))?;
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }
    pub fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    pub fn f64(&mut self) -> Result<f64, String> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(f64::from_le_bytes(a))
    }
    pub fn f64s(&mut self) -> Result<Vec<f64>, String> {
        let n = self.u32()? as usize;
        if n > self.bytes.len() / 8 {
            return Err(format!("the state claims {n} numbers, more than its length holds"));
        }
        (0..n).map(|_| self.f64()).collect()
    }
    /// What `ByteWriter::optional_f64s` wrote: exactly `N` finite numbers if the flag is 1
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
                "{} unexpected bytes after the state",
                self.bytes.len() - self.at
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_rejections() {
        let mut w = ByteWriter::new(b"M", 1, "0.1.0");
        w.f64s(&[1.0, 2.0]);
        w.f64(3.0);
        let bytes = w.0;
        let mut r = ByteReader::open(&bytes, b"M", 1, "0.1.0", "M").unwrap();
        assert_eq!(r.f64s().unwrap(), vec![1.0, 2.0]);
        assert_eq!(r.f64().unwrap(), 3.0);
        r.finish().unwrap();
        assert!(ByteReader::open(&bytes, b"X", 1, "0.1.0", "M").is_err());
        assert!(ByteReader::open(&bytes, b"M", 2, "0.1.0", "M").is_err());
        let mut r = ByteReader::open(&bytes[..bytes.len() - 3], b"M", 1, "0.1.0", "M").unwrap();
        r.f64s().unwrap();
        assert!(r.f64().unwrap_err().contains("truncated"));
    }

    #[test]
    fn optional_numbers_round_trip_and_are_checked() {
        let f = StateFormat {
            magic: b"M",
            version: 1,
            crate_version: "0.1.0",
            model: "M",
        };
        let mut w = f.writer();
        w.optional_f64s::<2>(None);
        w.optional_f64s(Some([1.0, 2.0]));
        w.optional_f64s(Some([f64::NAN]));
        let bytes = w.0;
        let mut r = f.reader(&bytes).unwrap();
        assert_eq!(r.optional_f64s::<2>("x").unwrap(), None);
        assert!(r
            .optional_f64s::<3>("x")
            .unwrap_err()
            .contains("2 x values, expected 3"));
        assert!(r.optional_f64s::<1>("x").unwrap_err().contains("non-finite"));
        r.finish().unwrap();
    }
}
