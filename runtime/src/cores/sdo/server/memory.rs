//! [`MemoryStore`]: an object dictionary held in memory, for tests,
//! simulations and benchmarks.

use alloc::collections::BTreeMap;
use alloc::vec::Vec;

use super::ObjectStore;
use crate::od::AccessRight;
use crate::sdo::AbortCode;

/// One value of a [`MemoryStore`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StoredValue {
    access: AccessRight,
    fixed: bool,
    data: Vec<u8>,
}

impl StoredValue {
    /// The access right over SDO.
    pub fn access(&self) -> AccessRight {
        self.access
    }

    /// The length every write must have, for fixed-size values.
    pub fn fixed_size(&self) -> Option<usize> {
        self.fixed.then_some(self.data.len())
    }

    /// The current value.
    pub fn data(&self) -> &[u8] {
        &self.data
    }

    fn readable(&self) -> bool {
        !matches!(self.access, AccessRight::Wo)
    }

    fn writable(&self) -> bool {
        !matches!(self.access, AccessRight::Ro | AccessRight::Const)
    }

    /// Whether a write of `len` bytes fits a fixed-size value.
    fn check_len(&self, len: usize) -> Result<(), AbortCode> {
        match self.fixed_size() {
            Some(size) if len > size => Err(AbortCode::LengthTooHigh),
            Some(size) if len < size => Err(AbortCode::LengthTooLow),
            _ => Ok(()),
        }
    }
}

/// An [`ObjectStore`] in memory: a map from (index, sub-index) to values,
/// each with an access right and, optionally, a fixed length.
///
/// Abort codes: missing index 0x06020000, missing sub-index of an existing
/// index 0x06090011, read of a write-only value 0x06010001, write of a
/// read-only or constant one 0x06010002, write of another length to a
/// fixed-size value 0x06070012 (longer) or 0x06070013 (shorter).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MemoryStore {
    entries: BTreeMap<(u16, u8), StoredValue>,
}

impl MemoryStore {
    /// An empty store.
    pub fn new() -> MemoryStore {
        MemoryStore::default()
    }

    /// Adds (or replaces) a value of any length.
    pub fn insert(&mut self, index: u16, sub: u8, access: AccessRight, bytes: &[u8]) {
        self.put(index, sub, access, bytes, false);
    }

    /// Adds (or replaces) a value whose writes must keep its length
    /// (`bytes.len()`), like a value of a basic numeric type.
    pub fn insert_fixed(&mut self, index: u16, sub: u8, access: AccessRight, bytes: &[u8]) {
        self.put(index, sub, access, bytes, true);
    }

    fn put(&mut self, index: u16, sub: u8, access: AccessRight, bytes: &[u8], fixed: bool) {
        let value = StoredValue {
            access,
            fixed,
            data: bytes.to_vec(),
        };
        self.entries.insert((index, sub), value);
    }

    /// The current value of (index, sub).
    pub fn get(&self, index: u16, sub: u8) -> Option<&[u8]> {
        self.entries.get(&(index, sub)).map(StoredValue::data)
    }

    /// The entry of (index, sub), with its access right and length rule.
    pub fn entry(&self, index: u16, sub: u8) -> Option<&StoredValue> {
        self.entries.get(&(index, sub))
    }

    /// Replaces the value of an existing entry from the application side
    /// (no access or length check); `false` when there is no such entry.
    pub fn set(&mut self, index: u16, sub: u8, bytes: &[u8]) -> bool {
        match self.entries.get_mut(&(index, sub)) {
            Some(value) => {
                value.data.clear();
                value.data.extend_from_slice(bytes);
                true
            }
            None => false,
        }
    }

    /// Removes an entry, returning it.
    pub fn remove(&mut self, index: u16, sub: u8) -> Option<StoredValue> {
        self.entries.remove(&(index, sub))
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the store has no entries.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The entry, or the abort code telling whether the index or only the
    /// sub-index is missing.
    fn lookup(&mut self, index: u16, sub: u8) -> Result<&mut StoredValue, AbortCode> {
        let index_exists = self
            .entries
            .range((index, 0)..=(index, u8::MAX))
            .next()
            .is_some();
        match self.entries.get_mut(&(index, sub)) {
            Some(value) => Ok(value),
            None if index_exists => Err(AbortCode::SubindexDoesNotExist),
            None => Err(AbortCode::ObjectDoesNotExist),
        }
    }
}

impl ObjectStore for MemoryStore {
    fn read(&mut self, index: u16, sub: u8, out: &mut Vec<u8>) -> Result<(), AbortCode> {
        let value = self.lookup(index, sub)?;
        if !value.readable() {
            return Err(AbortCode::ReadWriteOnly);
        }
        out.extend_from_slice(&value.data);
        Ok(())
    }

    fn check_write(&mut self, index: u16, sub: u8, size: Option<usize>) -> Result<(), AbortCode> {
        let value = self.lookup(index, sub)?;
        if !value.writable() {
            return Err(AbortCode::WriteReadOnly);
        }
        match size {
            Some(len) => value.check_len(len),
            None => Ok(()),
        }
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), AbortCode> {
        let value = self.lookup(index, sub)?;
        if !value.writable() {
            return Err(AbortCode::WriteReadOnly);
        }
        value.check_len(data.len())?;
        // Reuses the value's allocation when it is large enough.
        value.data.clear();
        value.data.extend_from_slice(data);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn store() -> MemoryStore {
        let mut store = MemoryStore::new();
        store.insert_fixed(0x1000, 0, AccessRight::Ro, &[0x92, 0x01, 0x02, 0x00]);
        store.insert_fixed(0x1017, 0, AccessRight::Rw, &[0xE8, 0x03]);
        store.insert(0x2000, 1, AccessRight::Wo, &[]);
        store.insert(0x2000, 2, AccessRight::Rw, b"abc");
        store
    }

    #[test]
    fn reads_and_writes_follow_the_access_rights() {
        let mut store = store();
        let mut out = Vec::new();
        assert_eq!(store.read(0x1000, 0, &mut out), Ok(()));
        assert_eq!(out, [0x92, 0x01, 0x02, 0x00]);
        assert_eq!(
            store.read(0x2000, 1, &mut Vec::new()),
            Err(AbortCode::ReadWriteOnly)
        );
        assert_eq!(
            store.write(0x1000, 0, &[0; 4]),
            Err(AbortCode::WriteReadOnly)
        );
        assert_eq!(
            store.check_write(0x1000, 0, None),
            Err(AbortCode::WriteReadOnly)
        );
        assert_eq!(store.write(0x2000, 1, b"hello"), Ok(()));
        assert_eq!(store.get(0x2000, 1), Some(&b"hello"[..]));
        assert_eq!(store.write(0x2000, 2, b""), Ok(()));
        assert_eq!(store.get(0x2000, 2), Some(&b""[..]));
    }

    #[test]
    fn missing_index_and_missing_sub_index_differ() {
        let mut store = store();
        let mut out = Vec::new();
        assert_eq!(
            store.read(0x3000, 0, &mut out),
            Err(AbortCode::ObjectDoesNotExist)
        );
        assert_eq!(
            store.read(0x2000, 3, &mut out),
            Err(AbortCode::SubindexDoesNotExist)
        );
        assert_eq!(
            store.check_write(0x2000, 0, Some(1)),
            Err(AbortCode::SubindexDoesNotExist)
        );
        assert_eq!(
            store.write(0x1FFF, 0, &[1]),
            Err(AbortCode::ObjectDoesNotExist)
        );
        assert_eq!(AbortCode::ObjectDoesNotExist.code(), 0x0602_0000);
        assert_eq!(AbortCode::SubindexDoesNotExist.code(), 0x0609_0011);
    }

    #[test]
    fn fixed_size_values_keep_their_length() {
        let mut store = store();
        assert_eq!(
            store.check_write(0x1017, 0, Some(4)),
            Err(AbortCode::LengthTooHigh)
        );
        assert_eq!(store.write(0x1017, 0, &[1]), Err(AbortCode::LengthTooLow));
        assert_eq!(store.check_write(0x1017, 0, Some(2)), Ok(()));
        assert_eq!(store.write(0x1017, 0, &[0xD0, 0x07]), Ok(()));
        assert_eq!(store.get(0x1017, 0), Some(&[0xD0, 0x07][..]));
        assert_eq!(
            store.entry(0x1017, 0).and_then(StoredValue::fixed_size),
            Some(2)
        );
        assert_eq!(
            store.entry(0x2000, 2).and_then(StoredValue::fixed_size),
            None
        );
    }

    #[test]
    fn application_side_updates() {
        let mut store = store();
        assert!(store.set(0x1000, 0, &[1, 2, 3, 4]));
        assert_eq!(store.get(0x1000, 0), Some(&[1, 2, 3, 4][..]));
        assert!(!store.set(0x1001, 0, &[1]));
        assert_eq!(store.len(), 4);
        assert!(store.remove(0x2000, 1).is_some());
        assert_eq!(store.len(), 3);
        assert!(!store.is_empty());
    }
}
