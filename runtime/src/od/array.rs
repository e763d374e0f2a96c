//! ARRAY objects as one indexed type.
//!
//! Generated code describes the elements of an ARRAY (subs 1 to N sharing
//! one data type, access right and value type) as one zero-sized type with a
//! const parameter, `PreDefinedErrorField<const SUB: u8 = 0>`:
//!
//! - `PreDefinedErrorField<3>` is element 3, an [`Entry`] like any other;
//!   a sub-index outside the array fails to compile (the evaluation of its
//!   `SUBINDEX` fails, naming the type);
//! - `PreDefinedErrorField` alone (`<0>`: sub 0 is the array's count, never
//!   an element) names the whole array: it implements [`Array`], and
//!   [`Element<PreDefinedErrorField>`] is an element chosen at run time,
//!   with a checked constructor ([`Element::new`]) and iteration over the
//!   valid subs ([`Element::all`]). The SDO clients take it (`read_at`,
//!   `write_at`, ...) and so do the PDO mapping functions
//!   ([`Element::rpdo_mapping_entry`], [`Element::tpdo_mapping_entry`]).

use core::fmt;
use core::marker::PhantomData;

use super::{Entry, PdoMappable, RpdoAccess, TpdoAccess, mapping_bits};

/// An ARRAY's elements as one type: implemented by the generated indexed
/// type without its sub-index (`PreDefinedErrorField`, that is `<0>`).
///
/// Its [`Entry`] items (index, name, data type, access right, value type,
/// PDO mappability) are those of every element; its `SUBINDEX` does not
/// exist (evaluating it fails to compile), only [`Array::FIRST`] to
/// [`Array::LAST`] do.
pub trait Array: Entry {
    /// The lowest sub-index of an element.
    const FIRST: u8;
    /// The highest sub-index of an element.
    const LAST: u8;
}

/// `sub` when it is an element of `A`; evaluated at compile time in the
/// `SUBINDEX` of a generated indexed type, where a sub-index out of range
/// stops the build.
pub const fn array_subindex<A: Array>(sub: u8) -> u8 {
    assert!(
        sub >= A::FIRST && sub <= A::LAST,
        "sub-index out of the array's range (see the type's FIRST and LAST)"
    );
    sub
}

/// One element of array `A`, chosen at run time: a sub-index checked
/// against the array's range.
pub struct Element<A> {
    sub: u8,
    array: PhantomData<fn() -> A>,
}

impl<A: Array> Element<A> {
    /// The element at `sub`; `None` outside [`Array::FIRST`] to
    /// [`Array::LAST`].
    pub const fn new(sub: u8) -> Option<Element<A>> {
        if sub >= A::FIRST && sub <= A::LAST {
            Some(Element {
                sub,
                array: PhantomData,
            })
        } else {
            None
        }
    }

    /// Every element, in sub-index order.
    pub fn all() -> Elements<A> {
        Elements {
            next: A::FIRST,
            end: A::LAST as u16 + 1,
            array: PhantomData,
        }
    }

    /// The number of elements.
    pub const fn count() -> usize {
        (A::LAST - A::FIRST) as usize + 1
    }

    /// The object's index.
    pub const fn index(self) -> u16 {
        A::INDEX
    }

    /// The element's sub-index.
    pub const fn subindex(self) -> u8 {
        self.sub
    }

    /// The mapping value of this element in an RPDO (`index << 16 | subindex
    /// << 8 | bits`), checked as [`super::rpdo_mapping_entry`] checks an
    /// entry: the array must be PDO-mappable and writable.
    pub const fn rpdo_mapping_entry(self) -> u32
    where
        A: PdoMappable,
        A::Access: RpdoAccess<A>,
    {
        mapping_bits(A::INDEX, self.sub, A::DATA_TYPE)
    }

    /// The mapping value of this element in a TPDO, checked as
    /// [`super::tpdo_mapping_entry`] checks an entry: the array must be
    /// PDO-mappable and readable.
    pub const fn tpdo_mapping_entry(self) -> u32
    where
        A: PdoMappable,
        A::Access: TpdoAccess<A>,
    {
        mapping_bits(A::INDEX, self.sub, A::DATA_TYPE)
    }
}

// By hand: a derive would ask `A` for the traits, which an entry type
// need not have.
impl<A> Clone for Element<A> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<A> Copy for Element<A> {}
impl<A> PartialEq for Element<A> {
    fn eq(&self, other: &Self) -> bool {
        self.sub == other.sub
    }
}
impl<A> Eq for Element<A> {}
impl<A> PartialOrd for Element<A> {
    fn partial_cmp(&self, other: &Self) -> Option<core::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl<A> Ord for Element<A> {
    fn cmp(&self, other: &Self) -> core::cmp::Ordering {
        self.sub.cmp(&other.sub)
    }
}
impl<A> core::hash::Hash for Element<A> {
    fn hash<H: core::hash::Hasher>(&self, state: &mut H) {
        self.sub.hash(state);
    }
}

impl<A: Array> fmt::Debug for Element<A> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (0x{:04X} sub {})", A::NAME, A::INDEX, self.sub)
    }
}

impl<A: Array> fmt::Display for Element<A> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:04X}.{}", A::INDEX, self.sub)
    }
}

/// The elements of an array in sub-index order ([`Element::all`]).
pub struct Elements<A> {
    next: u8,
    /// One past the last sub-index (256 when the array ends at 255).
    end: u16,
    array: PhantomData<fn() -> A>,
}

impl<A: Array> Iterator for Elements<A> {
    type Item = Element<A>;

    fn next(&mut self) -> Option<Element<A>> {
        if u16::from(self.next) >= self.end {
            return None;
        }
        let element = Element::new(self.next);
        if self.next == u8::MAX {
            self.end = 0;
        } else {
            self.next += 1;
        }
        element
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = usize::from(self.end.saturating_sub(u16::from(self.next)));
        (left, Some(left))
    }
}

impl<A: Array> ExactSizeIterator for Elements<A> {}

impl<A: Array> DoubleEndedIterator for Elements<A> {
    fn next_back(&mut self) -> Option<Element<A>> {
        if u16::from(self.next) >= self.end {
            return None;
        }
        self.end -= 1;
        Element::new(self.end as u8)
    }
}

impl<A> Clone for Elements<A> {
    fn clone(&self) -> Self {
        Elements {
            next: self.next,
            end: self.end,
            array: PhantomData,
        }
    }
}

impl<A> fmt::Debug for Elements<A> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Elements")
            .field("next", &self.next)
            .field("end", &self.end)
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::{DataType, access};

    /// What generated code declares for an array of subs `LOW..=HIGH`.
    struct Field<const SUB: u8 = 0>;
    impl<const SUB: u8> Entry for Field<SUB> {
        const INDEX: u16 = 0x1003;
        const SUBINDEX: u8 = array_subindex::<Field>(SUB);
        const NAME: &'static str = "Standard error field";
        const DATA_TYPE: DataType = DataType::Unsigned32;
        const PDO_MAPPABLE: bool = true;
        type Access = access::Ro;
        type Value = u32;
    }
    impl Array for Field {
        const FIRST: u8 = 1;
        const LAST: u8 = 4;
    }
    impl<const SUB: u8> PdoMappable for Field<SUB> {}

    struct Top;
    impl Entry for Top {
        const INDEX: u16 = 0x2000;
        const SUBINDEX: u8 = 0;
        const NAME: &'static str = "Top";
        const DATA_TYPE: DataType = DataType::Unsigned8;
        const PDO_MAPPABLE: bool = false;
        type Access = access::Rw;
        type Value = u8;
    }
    impl Array for Top {
        const FIRST: u8 = 250;
        const LAST: u8 = 255;
    }

    #[test]
    fn elements_are_checked_and_iterate_in_order() {
        assert_eq!(<Field<3> as Entry>::SUBINDEX, 3);
        assert!(Element::<Field>::new(0).is_none());
        assert!(Element::<Field>::new(5).is_none());
        let subs: Vec<u8> = Element::<Field>::all().map(Element::subindex).collect();
        assert_eq!(subs, [1, 2, 3, 4]);
        let back: Vec<u8> = Element::<Field>::all()
            .rev()
            .map(Element::subindex)
            .collect();
        assert_eq!(back, [4, 3, 2, 1]);
        assert_eq!(Element::<Field>::all().len(), 4);
        assert_eq!(Element::<Field>::count(), 4);
        let e = Element::<Field>::new(2).unwrap();
        assert_eq!(e.tpdo_mapping_entry(), 0x1003_0220);
        assert_eq!(
            format!("{e} {e:?}"),
            "0x1003.2 Standard error field (0x1003 sub 2)"
        );
    }

    #[test]
    fn an_array_may_end_at_sub_255() {
        let subs: Vec<u8> = Element::<Top>::all().map(Element::subindex).collect();
        assert_eq!(subs, [250, 251, 252, 253, 254, 255]);
        let mut it = Element::<Top>::all();
        assert_eq!(it.next_back().map(Element::subindex), Some(255));
        assert_eq!(it.len(), 5);
        assert!(Element::<Top>::new(255).is_some());
    }
}
