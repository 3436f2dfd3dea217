"""The model description against MODEL.md's interface and the thesis's Table 3.1 defaults."""

import zipfile

from fmpy.validation import validate_fmu
import pytest

# name: (causality, unit, value reference, start or None)
INTERFACE = {
    "v_DA": ("input", "V", 1, 0.0),
    "x_s": ("input", "m", 2, 0.054),
    "a_s": ("input", "m/s2", 3, 0.0),
    "F_act": ("output", "N", 10, None),
    "P1": ("output", "Pa", 11, None),
    "P2": ("output", "Pa", 12, None),
    "i": ("output", "A", 13, None),
    "x_jp": ("output", "m", 14, None),
    "F_meas": ("output", "N", 15, None),
    "P1_meas": ("output", "Pa", 16, None),
    "P2_meas": ("output", "Pa", 17, None),
}

# MODEL.md defaults and Table 3.1 of the thesis, with their units.
PARAMETERS = {
    "P_s": (652925.0, "Pa"),
    "P_r": (101325.0, "Pa"),
    "T": (293.15, "K"),
    "gamma": (1.4, None),
    "R_gas": (287.0, None),
    "k_cd": (0.04, "A/V"),
    "i_offset": (0.0, "A"),
    "omega_cd": (7050.0, "rad/s"),
    "k_m": (1.946, "N/A"),
    "omega_1": (973.9, "rad/s"),
    "omega_2": (1856.7, "rad/s"),
    "zeta_2": (0.019, None),
    "x_jp_sat": (0.5e-3, "m"),
    "F_jp_sat": (0.45, "N"),
    "D_jp": (0.9652e-3, "m"),
    "x_jp_offset": (0.099e-3, "m"),
    "C_d": (0.696, None),
    "C_db_A_lpp": (0.0971e-6, None),
    "C_dm_A_lpp": (-0.0475e-6, None),
    "L_cyl": (0.078, "m"),
    "L_p": (0.008, "m"),
    "L_s": (0.007, "m"),
    "L_sup": (0.011, "m"),
    "L_spring0": (0.0691, "m"),
    "D_cyl": (0.015875, "m"),
    "k_spring": (88.14, "N/m"),
    # the effects of MODEL.md, all off at their start values
    "hysteresis_width": (0.0, "m"),
    "hysteresis_deadband": (0.0, "m"),
    "friction_coulomb": (0.0, "N"),
    "dead_volume_1": (0.0, "m3"),
    "dead_volume_2": (0.0, "m3"),
    "supply_resistance": (0.0, "Pa.s/kg"),
    "heat_transfer_fraction": (0.0, "1"),
    "command_delay": (0.0, "s"),
    "force_sensor_offset": (0.0, "N"),
    "force_sensor_gain": (1.0, "1"),
    # generic correction terms of the diagnosis, all off at their start values
    "supply_area_scale_1": (1.0, "1"),
    "supply_area_scale_2": (1.0, "1"),
    "return_area_scale_1": (1.0, "1"),
    "return_area_scale_2": (1.0, "1"),
    "return_resistance": (0.0, "Pa.s/kg"),
    "chamber_vent_1": (0.0, "m2"),
    "chamber_vent_2": (0.0, "m2"),
    "port_resistance_1": (0.0, "Pa.s/kg"),
    "port_resistance_2": (0.0, "Pa.s/kg"),
    "stopper_compliance": (0.0, "m/N"),
}


def test_validate_fmu(fmu_path):
    problems = validate_fmu(str(fmu_path))
    assert problems == [], "\n".join(problems)


def test_model_identifier_and_capabilities(model_description):
    md = model_description
    assert md.fmiVersion == "2.0"
    assert md.coSimulation is not None, "not a Co-Simulation FMU"
    cs = md.coSimulation
    assert cs.modelIdentifier == "JetPipeActuator"
    assert cs.canHandleVariableCommunicationStepSize
    assert cs.canInterpolateInputs
    assert cs.canGetAndSetFMUstate
    assert cs.canSerializeFMUstate


def test_interface_variables(model_description):
    by_name = {v.name: v for v in model_description.modelVariables}
    for name, (causality, unit, vr, start) in INTERFACE.items():
        assert name in by_name, f"{name} missing"
        v = by_name[name]
        assert v.type == "Real", name
        assert v.causality == causality, f"{name}: causality {v.causality}"
        assert v.unit == unit, f"{name}: unit {v.unit!r}"
        assert v.valueReference == vr, f"{name}: value reference {v.valueReference}"
        if causality == "input":
            assert v.variability == "continuous", name
            assert v.start is not None and float(v.start) == start, f"{name}: start {v.start}"
        else:
            assert v.variability == "continuous", name
    outputs = {u.variable.name for u in model_description.outputs}
    assert outputs == {n for n, row in INTERFACE.items() if row[0] == "output"}


def test_parameter_defaults(model_description):
    by_name = {v.name: v for v in model_description.modelVariables}
    wrong = []
    for name, (value, unit) in PARAMETERS.items():
        assert name in by_name, f"parameter {name} missing"
        v = by_name[name]
        assert v.causality == "parameter", f"{name}: causality {v.causality}"
        assert v.variability == "fixed", f"{name}: variability {v.variability}"
        assert v.type == "Real", name
        if unit is not None:
            assert v.unit == unit, f"{name}: unit {v.unit!r}, expected {unit!r}"
        if v.start is None or float(v.start) != pytest.approx(value, rel=1e-12, abs=0.0):
            wrong.append(f"{name}: start {v.start}, expected {value}")
    assert not wrong, "\n".join(wrong)


def test_initialisation_parameters(model_description):
    by_name = {v.name: v for v in model_description.modelVariables}
    eq = by_name["start_at_equilibrium"]
    assert eq.type == "Boolean"
    assert eq.causality == "parameter"
    assert eq.start in ("true", "1", True)
    for name in ("P1_start", "P2_start"):
        v = by_name[name]
        assert v.type == "Real" and v.causality == "parameter" and v.unit == "Pa", name


def test_zip_contents(fmu_path):
    with zipfile.ZipFile(fmu_path) as zf:
        names = set(zf.namelist())
        assert zf.testzip() is None
    for required in ("modelDescription.xml", "binaries/linux64/JetPipeActuator.so", "documentation/index.html"):
        assert required in names, f"{required} missing from the FMU; it holds {sorted(names)}"
