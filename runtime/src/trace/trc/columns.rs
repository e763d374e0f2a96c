//! The column layout of version 2 lines (`;$COLUMNS=`).

use core::fmt;
use core::str::SplitAsciiWhitespace;

use super::Reason;
use super::fields::is_digits;

/// One column of a version 2 message line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Column {
    /// `N`: the message number.
    Number,
    /// `O`: the time offset in milliseconds.
    Offset,
    /// `T`: the message type (`DT`, `RR`, `ER`, ...).
    Type,
    /// `B`: the bus number (`-` for all buses).
    Bus,
    /// `I`: the identifier in hex.
    Id,
    /// `d`: the direction, `Rx` or `Tx`.
    Direction,
    /// `R`: reserved, `-`.
    Reserved,
    /// `L`: the data length code.
    Dlc,
    /// `l`: the data length in bytes.
    Length,
    /// `D`: the data bytes, to the end of the line.
    Data,
}

impl Column {
    /// The letter of `$COLUMNS`.
    pub const fn letter(self) -> char {
        match self {
            Column::Number => 'N',
            Column::Offset => 'O',
            Column::Type => 'T',
            Column::Bus => 'B',
            Column::Id => 'I',
            Column::Direction => 'd',
            Column::Reserved => 'R',
            Column::Dlc => 'L',
            Column::Length => 'l',
            Column::Data => 'D',
        }
    }

    fn from_letter(letter: &str) -> Option<Column> {
        Some(match letter {
            "N" => Column::Number,
            "O" => Column::Offset,
            "T" => Column::Type,
            "B" => Column::Bus,
            "I" => Column::Id,
            "d" => Column::Direction,
            "R" => Column::Reserved,
            "L" => Column::Dlc,
            "l" => Column::Length,
            "D" => Column::Data,
            _ => return None,
        })
    }

    /// The place of the column in the order the format prescribes (`L` and
    /// `l` share one).
    const fn rank(self) -> u8 {
        match self {
            Column::Number => 0,
            Column::Offset => 1,
            Column::Type => 2,
            Column::Bus => 3,
            Column::Id => 4,
            Column::Direction => 5,
            Column::Reserved => 6,
            Column::Dlc | Column::Length => 7,
            Column::Data => 8,
        }
    }
}

/// The most columns a layout has (one of each rank).
const MAX_COLUMNS: usize = 9;

/// The columns of version 2 lines, in order.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Columns {
    list: [Column; MAX_COLUMNS],
    len: u8,
}

impl Columns {
    /// The default of version 2.0: `N,O,T,I,d,l,D`.
    pub const V2_0: Columns = Columns::of(&[
        Column::Number,
        Column::Offset,
        Column::Type,
        Column::Id,
        Column::Direction,
        Column::Length,
        Column::Data,
    ]);

    /// The default of version 2.1: `N,O,T,B,I,d,R,L,D`.
    pub const V2_1: Columns = Columns::of(&[
        Column::Number,
        Column::Offset,
        Column::Type,
        Column::Bus,
        Column::Id,
        Column::Direction,
        Column::Reserved,
        Column::Dlc,
        Column::Data,
    ]);

    /// A layout from a list known to be valid (at most [`MAX_COLUMNS`]).
    const fn of(columns: &[Column]) -> Columns {
        let mut list = [Column::Data; MAX_COLUMNS];
        let mut i = 0;
        while i < columns.len() && i < MAX_COLUMNS {
            list[i] = columns[i];
            i += 1;
        }
        Columns { list, len: i as u8 }
    }

    /// Parses the value of `$COLUMNS` (`N,O,T,B,I,d,R,L,D`): known letters
    /// in the prescribed order, `O`, `T`, `I`, `L` or `l`, and `D` present,
    /// `D` last.
    pub fn parse(text: &str) -> Result<Columns, Reason> {
        let mut list = [Column::Data; MAX_COLUMNS];
        let mut len = 0usize;
        for letter in text.split(',') {
            let column = Column::from_letter(letter.trim_ascii())
                .ok_or(Reason::BadColumns("unknown column letter"))?;
            if let Some(last) = len.checked_sub(1).and_then(|i| list.get(i))
                && column.rank() <= last.rank()
            {
                return Err(Reason::BadColumns(
                    "columns repeated or out of the order N,O,T,B,I,d,R,L,D",
                ));
            }
            // Strictly rising ranks: never more than MAX_COLUMNS.
            let slot = list
                .get_mut(len)
                .ok_or(Reason::BadColumns("too many columns"))?;
            *slot = column;
            len += 1;
        }
        let columns = Columns {
            list,
            len: len as u8,
        };
        let has = |wanted: &[Column]| columns.as_slice().iter().any(|c| wanted.contains(c));
        let required = [
            has(&[Column::Offset]),
            has(&[Column::Type]),
            has(&[Column::Id]),
            has(&[Column::Dlc, Column::Length]),
            has(&[Column::Data]),
        ];
        if required.contains(&false) {
            return Err(Reason::BadColumns(
                "expected at least O, T, I, L (or l) and D",
            ));
        }
        Ok(columns)
    }

    /// The columns in order.
    pub fn as_slice(&self) -> &[Column] {
        self.list.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// The layout of a version 2 line without a header: `N` when the line
    /// starts with a whole number (not an offset with a fraction), and the
    /// 2.1 columns (`B` and `R`) when a bus number or `-` follows the type,
    /// else those of 2.0.
    pub(super) fn guess(first: &str, mut rest: SplitAsciiWhitespace<'_>) -> Columns {
        let numbered = is_digits(first);
        if !numbered {
            // `first` is the offset; the type follows.
            rest.next();
        } else {
            rest.next(); // the offset
            rest.next(); // the type
        }
        let after_type = rest.next().unwrap_or("");
        let bus = after_type == "-" || (is_digits(after_type) && after_type.len() <= 3);
        let mut columns = if bus { Columns::V2_1 } else { Columns::V2_0 };
        if !numbered {
            columns.remove_first();
        }
        columns
    }

    /// Drops the first column (the `N` of a default layout).
    fn remove_first(&mut self) {
        self.list.rotate_left(1);
        self.len = self.len.saturating_sub(1);
    }
}

impl fmt::Display for Columns {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, column) in self.as_slice().iter().enumerate() {
            if i > 0 {
                f.write_str(",")?;
            }
            write!(f, "{}", column.letter())?;
        }
        Ok(())
    }
}

impl fmt::Debug for Columns {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Columns({self})")
    }
}
