//! The interface checks every model's tests make. Not `#[cfg(test)]`: the tests that use
//! them are in the model crates.

use fmi2::model::{ModelInfo, Variable};
use fmi2::model_description::model_description_xml;

/// The interface tests of a model's `fmu` module: `checked_in` is its
/// `include_str!("../modelDescription.xml")`, `vrs` every constant of its `vr` module.
#[macro_export]
macro_rules! interface_tests {
    (model: $model:ty, info: $info:expr, dir: $dir:expr, checked_in: $checked_in:expr, vrs: [$($vr:expr),* $(,)?] $(,)?) => {
        #[test]
        fn declared_dependencies_are_what_perturbations_show() {
            let report = $crate::__fmi2::structure_check::check_dependencies::<$model>(1e-3);
            assert!(report.problems.is_empty(), "{:#?}", report.problems);
        }

        #[test]
        fn checked_in_model_description_is_the_generated_one() {
            $crate::testing::assert_model_description_is_current($checked_in, &$info, $dir);
        }

        #[test]
        fn every_vr_constant_is_in_the_table() {
            $crate::testing::assert_vr_constants_match_the_table($info.variables, &[$($vr),*]);
        }
    };
}

/// The checked-in `<dir>/modelDescription.xml` (`checked_in`, from `include_str!`) must be
/// the one generated from `info`: the archives are written from `info`, so a stale file
/// would mislead only its readers, and nothing else would notice.
pub fn assert_model_description_is_current(checked_in: &str, info: &ModelInfo, dir: &str) {
    let name = info.model_identifier;
    assert_eq!(
        checked_in,
        model_description_xml(info),
        "{dir}/modelDescription.xml is stale: regenerate it with \
         `cargo run --release -p antagonistic -- model-description {name} > {dir}/modelDescription.xml`"
    );
}

/// `vrs` (every constant of the model's `vr` module) and the table's value references are
/// the same set: `Values::get` panics on a value reference that is not in the table.
pub fn assert_vr_constants_match_the_table(table: &[Variable], vrs: &[u32]) {
    for (i, &r) in vrs.iter().enumerate() {
        assert!(table.iter().any(|v| v.value_reference == r), "{r}");
        assert!(!vrs[..i].contains(&r), "{r} twice");
    }
    assert_eq!(table.len(), vrs.len());
}
