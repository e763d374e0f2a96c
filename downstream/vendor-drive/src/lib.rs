//! The Elmo Gold drive's object dictionary, generated at build time, and
//! the application's own PDO mappings over it (`#[derive(Pdo)]`, which the
//! runtime's `derive` feature provides without `std`).
#![no_std]
#![forbid(unsafe_code)]

pub mod drive {
    include!(concat!(env!("OUT_DIR"), "/drive.rs"));
}

/// The PDOs this application maps, in place of the drive's defaults.
pub mod mapping {
    use crate::drive::od;
    use eds2rust_runtime::Pdo;
    use eds2rust_runtime::od::Entry;

    /// What the control loop reads: statusword, position and the mode the
    /// drive is in.
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 2)]
    pub struct StatusPosition {
        #[pdo(entry = od::Statusword)]
        pub status: od::StatuswordValue,
        #[pdo(entry = od::PositionActualValue)]
        pub position: i32,
        #[pdo(entry = od::ModesOfOperation)]
        pub mode: od::ModesOfOperationValue,
    }

    /// What the control loop writes: controlword and target velocity.
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 1)]
    pub struct ControlVelocity {
        #[pdo(entry = od::Controlword)]
        pub control: <od::Controlword as Entry>::Value,
        #[pdo(entry = od::TargetVelocity)]
        pub velocity: <od::TargetVelocity as Entry>::Value,
    }
}
