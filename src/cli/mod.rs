//! The subcommands of the command line, one file each.

pub mod adapt;
pub mod args;
pub mod check;
pub mod corners;
pub mod malloc;
pub mod out;
pub mod plan;
pub mod plan_adaptive;
pub mod run;
pub mod study;
pub mod summary;
