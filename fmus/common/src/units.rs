//! Unit definitions (SI base-unit exponents) used by the three models' tables. Radians are
//! dimensionless in FMI's `<BaseUnit>` (the `rad` exponent is optional), so `rad` and `1`
//! share exponents but keep their names for the reader.

use fmi2::model::UnitDefinition;

const fn unit(name: &'static str, kg: i32, m: i32, s: i32, a: i32) -> UnitDefinition {
    UnitDefinition {
        name,
        kg,
        m,
        s,
        a,
        k: 0,
    }
}

pub const M: UnitDefinition = unit("m", 0, 1, 0, 0);
pub const M_PER_S: UnitDefinition = unit("m/s", 0, 1, -1, 0);
pub const N: UnitDefinition = unit("N", 1, 1, -2, 0);
pub const N_PER_M: UnitDefinition = unit("N/m", 1, 0, -2, 0);
pub const N_S_PER_M: UnitDefinition = unit("N.s/m", 1, 0, -1, 0);
pub const KG: UnitDefinition = unit("kg", 1, 0, 0, 0);
pub const S: UnitDefinition = unit("s", 0, 0, 1, 0);
pub const ONE: UnitDefinition = unit("1", 0, 0, 0, 0);
pub const RAD: UnitDefinition = unit("rad", 0, 0, 0, 0);
pub const RAD_PER_S: UnitDefinition = unit("rad/s", 0, 0, -1, 0);
pub const KG_M2: UnitDefinition = unit("kg.m2", 1, 2, 0, 0);
pub const N_M: UnitDefinition = unit("N.m", 1, 2, -2, 0);
pub const N_M_PER_RAD: UnitDefinition = unit("N.m/rad", 1, 2, -2, 0);
pub const N_M_S_PER_RAD: UnitDefinition = unit("N.m.s/rad", 1, 2, -1, 0);
pub const N_M_PER_RAD_S: UnitDefinition = unit("N.m/(rad.s)", 1, 2, -3, 0);
pub const V: UnitDefinition = unit("V", 1, 2, -3, -1);
pub const V_PER_N: UnitDefinition = unit("V/N", 0, 1, -1, -1);
