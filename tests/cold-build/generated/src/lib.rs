//! The Elmo Gold drive's object dictionary, generated at build time, and an
//! application's PDO mappings over it (`#[derive(Pdo)]`). The same mappings
//! over hand-written entries: ../runtime-only.
#![no_std]
#![forbid(unsafe_code)]

pub mod drive {
    include!(concat!(env!("OUT_DIR"), "/drive.rs"));
}

/// The PDOs the application maps.
pub mod mapping {
    use crate::drive::od;
    use eds2rust_runtime::Pdo;

    /// What the control loop reads: statusword, position and the mode the
    /// drive is in.
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 2)]
    pub struct StatusPosition {
        #[pdo(entry = od::Statusword)]
        pub status: od::StatuswordValue,
        #[pdo(entry = od::PositionActualValue)]
        pub position: i32,
        #[pdo(entry = od::ModesOfOperationDisplay)]
        pub mode: od::ModesOfOperationDisplayValue,
    }
}
