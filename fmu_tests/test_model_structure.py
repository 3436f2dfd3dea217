"""Every FMU's model description as third-party importers read it (issue 21): valid against the
FMI 2.0 XSD that FMPy ships, a GUID that is the version-5 UUID of the description's own content,
`dependencies` on every output that name inputs only (Outputs) or inputs and parameters
(InitialUnknowns), and min/max/nominal consistent with the start values.

Build what it needs with
    cargo run --release --bin jetpipe -- package
    cargo run --release -p antagonistic -- package
"""

from __future__ import annotations

import re
import uuid
import zipfile
from pathlib import Path

import fmpy
import pytest
from fmpy.validation import validate_fmu
from lxml import etree

REPO = Path(__file__).resolve().parents[1]
DIST = REPO / "dist"
SCHEMA = Path(fmpy.__file__).parent / "schema" / "fmi2" / "fmi2ModelDescription.xsd"

# model identifier -> checked-in model description
CHECKED_IN = {
    "JetPipeActuator": REPO / "modelDescription.xml",
    "Tendon": REPO / "fmus" / "tendon" / "modelDescription.xml",
    "FingerJoint": REPO / "fmus" / "finger_joint" / "modelDescription.xml",
    "JointController": REPO / "fmus" / "joint_controller" / "modelDescription.xml",
}


def fmu_file(name: str) -> Path:
    path = DIST / f"{name}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} not found: build the FMUs first (see this module's doc)", pytrace=False)
    return path


@pytest.fixture(scope="module")
def schema():
    return etree.XMLSchema(etree.parse(str(SCHEMA)))


@pytest.fixture(scope="module", params=sorted(CHECKED_IN))
def description(request):
    """(identifier, the XML text inside the FMU archive)."""
    with zipfile.ZipFile(fmu_file(request.param)) as zf:
        text = zf.read("modelDescription.xml").decode("utf-8")
    return request.param, text


def test_archive_holds_the_checked_in_description(description):
    name, text = description
    assert text == CHECKED_IN[name].read_text(encoding="utf-8"), f"{name}: archive and checked-in XML differ"


def test_valid_against_the_fmi2_xsd(description, schema):
    name, text = description
    doc = etree.fromstring(text.encode("utf-8"))
    ok = schema.validate(doc)
    assert ok, f"{name}: " + "\n".join(str(e) for e in schema.error_log)


def test_the_xsd_check_catches_a_broken_description(schema):
    """The schema check is not vacuous: a misspelt attribute value fails it."""
    text = CHECKED_IN["JetPipeActuator"].read_text(encoding="utf-8")
    broken = text.replace('dependenciesKind="dependent', 'dependenciesKind="depends', 1)
    assert broken != text
    assert not schema.validate(etree.fromstring(broken.encode("utf-8")))


def test_guid_is_the_uuid5_of_the_content(description):
    name, text = description
    guid = re.search(r' guid="([^"]*)"', text).group(1)
    without = text.replace(f' guid="{guid}"', ' guid=""', 1)
    expected = uuid.uuid5(uuid.NAMESPACE_URL, without)
    assert guid == "{" + str(expected) + "}", name
    assert uuid.UUID(guid.strip("{}")).version == 5


def test_fmpy_validation_is_clean(description):
    name, _ = description
    problems = validate_fmu(str(fmu_file(name)))
    assert problems == [], "\n".join(problems)


def test_dependencies_name_knowns_of_the_right_kind(description):
    name, _ = description
    md = fmpy.read_model_description(str(fmu_file(name)))
    inputs = {v for v in md.modelVariables if v.causality == "input"}
    knowns = inputs | {v for v in md.modelVariables if v.causality == "parameter"}
    # with Model Exchange the continuous states are knowns of the outputs as well
    states = {d.variable.derivative for d in md.derivatives}
    assert {u.variable for u in md.outputs} == {v for v in md.modelVariables if v.causality == "output"}
    for u in md.outputs:
        assert u.dependencies is not None, f"{name}.{u.variable.name}: no dependencies attribute"
        assert set(u.dependencies) <= inputs | states, f"{name}.{u.variable.name}"
        assert len(u.dependenciesKind) == len(u.dependencies)
    for u in md.initialUnknowns:
        assert u.dependencies is not None and set(u.dependencies) <= knowns, f"{name}.{u.variable.name}"
        assert set(u.dependenciesKind) <= {"dependent", "constant"}


def test_actuator_structure_and_bounds():
    md = fmpy.read_model_description(str(fmu_file("JetPipeActuator")))
    by_name = {v.name: v for v in md.modelVariables}
    states = {d.variable.derivative.name for d in md.derivatives}
    assert states == {"i", "x_jp", "x_jp_velocity", "x_jp_acceleration", "P1_at_mid_stroke", "P2_at_mid_stroke", "p_supply_plenum",
                      "p_return_plenum", "p_port_line_1", "p_port_line_2", "stopper_mount_load",
                      "command_lagged", "command_filtered", "command_filtered_rate", "F_meas_lagged", "F_meas_filtered", "F_meas_filtered_rate", "P1_meas_lagged", "P1_meas_filtered", "P1_meas_filtered_rate", "P2_meas_lagged", "P2_meas_filtered", "P2_meas_filtered_rate",
                      "command_delay_pade_1", "command_delay_pade_2", "command_delay_pade_3", "command_delay_pade_4", "command_delay_pade_5", "command_delay_pade_6", "command_delay_pade_7", "command_delay_pade_8"}
    # Model Exchange: every output may depend on every state; the inputs as in Co-Simulation
    assert all(states <= {d.name for d in u.dependencies} for u in md.outputs)
    direct = {u.variable.name: sorted(d.name for d in u.dependencies if d.name not in states) for u in md.outputs}
    # Only the stopper acts within a step (it moves at once, conserving the air), and its
    # acceleration on the forces (a force that follows it reads it at once); v_DA acts
    # through the current's dynamics.
    assert direct == {"F_act": ["a_s", "x_s"], "F_meas": ["a_s", "x_s"], "P1": ["x_s"], "P2": ["x_s"],
                      "P1_meas": ["x_s"], "P2_meas": ["x_s"], "i": [], "x_jp": []}
    a_s = by_name["a_s"]
    assert a_s.causality == "input" and float(a_s.min) == -1e4 and float(a_s.max) == 1e4
    x_s = by_name["x_s"]
    assert float(x_s.min) == pytest.approx(0.026) and float(x_s.max) == pytest.approx(0.096)
    assert float(by_name["C_d"].min) == 0.0 and float(by_name["C_d"].max) == 1.0
    assert float(by_name["v_DA"].min) == -10.0 and float(by_name["v_DA"].max) == 10.0
    for p in ("P_s", "P_r", "T", "R_gas", "D_cyl"):
        assert float(by_name[p].min) == 0.0, p
    for v in md.modelVariables:
        if v.type != "Real" or v.start is None:
            continue
        if v.min is not None:
            assert float(v.start) >= float(v.min), v.name
        if v.max is not None:
            assert float(v.start) <= float(v.max), v.name
        if v.nominal is not None:
            assert float(v.nominal) > 0, v.name


def test_parameters_have_their_default_as_nominal(description):
    name, _ = description
    md = fmpy.read_model_description(str(fmu_file(name)))
    missing = [
        v.name
        for v in md.modelVariables
        if v.causality == "parameter" and v.type == "Real" and float(v.start) != 0.0
        and (v.nominal is None or float(v.nominal) != abs(float(v.start)))
    ]
    assert not missing, f"{name}: no nominal = |start| for {missing}"
