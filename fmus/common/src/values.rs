//! The values of a model's parameters and inputs, one per row of its variable table, so the
//! getters, setters, range checks and FMU-state bytes all follow the table.

use fmi2::model::{Causality, VarType, Variable};

#[derive(Clone, Debug)]
pub struct Values {
    table: &'static [Variable],
    /// One value per table row (outputs keep their unused start so indices stay aligned).
    values: Vec<f64>,
}

impl Values {
    /// Every variable at its start value.
    pub fn starts(table: &'static [Variable]) -> Self {
        Self {
            table,
            values: table.iter().map(|v| v.start).collect(),
        }
    }

    fn row(&self, value_reference: u32) -> Option<usize> {
        self.table.iter().position(|v| v.value_reference == value_reference)
    }

    /// The table row of `value_reference`, for messages.
    pub fn variable(&self, value_reference: u32) -> Option<&'static Variable> {
        self.row(value_reference).map(|i| &self.table[i])
    }

    /// The value of a parameter or input. Panics on a value reference that is not in the
    /// table: models call this only with their own `vr` constants, which a test checks.
    pub fn get(&self, value_reference: u32) -> f64 {
        match self.row(value_reference) {
            Some(i) => self.values[i],
            None => panic!("value reference {value_reference} is not in the variable table"),
        }
    }

    /// The value of a parameter or input, or a message for an unknown one or an output.
    pub fn try_get(&self, value_reference: u32) -> Result<f64, String> {
        match self.row(value_reference) {
            Some(i) if matches!(self.table[i].causality, Causality::Parameter | Causality::Input) => Ok(self.values[i]),
            Some(i) => Err(format!("{} is not a parameter or input", self.table[i].name)),
            None => Err(format!("no variable with value reference {value_reference}")),
        }
    }

    /// Set a parameter or input after checking that the value is finite and within the
    /// table's [min, max]; the message names the variable, the value and the unit.
    pub fn set(&mut self, value_reference: u32, value: f64) -> Result<(), String> {
        let i = self
            .row(value_reference)
            .ok_or_else(|| format!("no variable with value reference {value_reference}"))?;
        let v = &self.table[i];
        if !matches!(v.causality, Causality::Parameter | Causality::Input) {
            return Err(format!("{} is an output and cannot be set", v.name));
        }
        check(v, value)?;
        self.values[i] = value;
        Ok(())
    }

    /// All values in table order (for the FMU-state bytes).
    pub fn as_slice(&self) -> &[f64] {
        &self.values
    }

    /// Restore from `as_slice` output, checking each value as `set` does.
    pub fn restore(&mut self, values: &[f64]) -> Result<(), String> {
        if values.len() != self.values.len() {
            return Err(format!(
                "the state holds {} values, this model has {}",
                values.len(),
                self.values.len()
            ));
        }
        for (v, &x) in self.table.iter().zip(values) {
            if matches!(v.causality, Causality::Parameter | Causality::Input) {
                check(v, x)?;
            }
        }
        self.values.copy_from_slice(values);
        Ok(())
    }
}

/// Finite, within [min, max], integral for Integer and Boolean variables.
pub fn check(v: &Variable, value: f64) -> Result<(), String> {
    let unit = v.unit.map_or(String::new(), |u| format!(" {u}"));
    if !value.is_finite() {
        return Err(format!("{} = {value}{unit} is invalid: must be finite", v.name));
    }
    if let Some(min) = v.min {
        if value < min {
            return Err(format!("{} = {value}{unit} is invalid: must be >= {min}{unit}", v.name));
        }
    }
    if let Some(max) = v.max {
        if value > max {
            return Err(format!("{} = {value}{unit} is invalid: must be <= {max}{unit}", v.name));
        }
    }
    if v.var_type != VarType::Real && value.fract() != 0.0 {
        return Err(format!("{} = {value} is invalid: must be an integer", v.name));
    }
    Ok(())
}

/// Table-row constructors shared by the three models (Real variables).
pub mod rows {
    use fmi2::model::{Causality, VarType, Variability, Variable};

    const fn real(
        name: &'static str,
        value_reference: u32,
        (causality, variability): (Causality, Variability),
        unit: &'static str,
        start: f64,
        range: (Option<f64>, Option<f64>),
        description: &'static str,
    ) -> Variable {
        Variable {
            name,
            value_reference,
            var_type: VarType::Real,
            causality,
            variability,
            unit: Some(unit),
            start,
            min: range.0,
            max: range.1,
            description,
        }
    }

    pub const fn input(
        name: &'static str,
        vr: u32,
        unit: &'static str,
        start: f64,
        range: (Option<f64>, Option<f64>),
        description: &'static str,
    ) -> Variable {
        real(
            name,
            vr,
            (Causality::Input, Variability::Continuous),
            unit,
            start,
            range,
            description,
        )
    }

    pub const fn output(name: &'static str, vr: u32, unit: &'static str, description: &'static str) -> Variable {
        real(
            name,
            vr,
            (Causality::Output, Variability::Continuous),
            unit,
            0.0,
            (None, None),
            description,
        )
    }

    pub const fn parameter(
        name: &'static str,
        vr: u32,
        unit: &'static str,
        start: f64,
        range: (Option<f64>, Option<f64>),
        description: &'static str,
    ) -> Variable {
        real(
            name,
            vr,
            (Causality::Parameter, Variability::Fixed),
            unit,
            start,
            range,
            description,
        )
    }

    /// Unbounded.
    pub const ANY: (Option<f64>, Option<f64>) = (None, None);
    /// > 0 is checked by the model; the table says >= 0 (FMI has no open bounds).
    pub const NON_NEGATIVE: (Option<f64>, Option<f64>) = (Some(0.0), None);
}

#[cfg(test)]
mod tests {
    use super::rows::*;
    use super::*;

    static TABLE: &[Variable] = &[
        parameter("k", 1, "N/m", 2.0, NON_NEGATIVE, "stiffness"),
        input("u", 2, "N", 0.0, ANY, "force"),
        output("y", 3, "m", "position"),
    ];

    #[test]
    fn set_checks_range_and_names_the_variable() {
        let mut v = Values::starts(TABLE);
        assert_eq!(v.get(1), 2.0);
        let e = v.set(1, -1.0).unwrap_err();
        assert!(e.contains("k = -1 N/m") && e.contains(">= 0"), "{e}");
        let e = v.set(2, f64::NAN).unwrap_err();
        assert!(e.contains("u = NaN") && e.contains("finite"), "{e}");
        assert!(v.set(3, 1.0).unwrap_err().contains("output"));
        assert_eq!(v.get(1), 2.0, "a rejected value is not applied");
        v.set(2, 5.0).unwrap();
        assert_eq!(v.get(2), 5.0);
    }

    #[test]
    fn restore_rejects_wrong_lengths_and_bad_values() {
        let mut v = Values::starts(TABLE);
        assert!(v.restore(&[1.0]).is_err());
        assert!(v.restore(&[-1.0, 0.0, 0.0]).is_err());
        v.restore(&[3.0, 4.0, 0.0]).unwrap();
        assert_eq!(v.get(1), 3.0);
    }
}
