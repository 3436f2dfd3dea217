//! Not compiled. `Cargo.toml` here only pins the versions of the dependencies that
//! `scripts/build_win64.sh` vendors and compiles with Debian's rustc 1.63; the crate roots it
//! compiles are those of the workspace: `crates/fmi2`, `crates/model` (rlibs) and the root
//! package's `src/` (the cdylib `JetPipeActuator.dll`).
