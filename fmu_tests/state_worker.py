"""Subprocess half of test_state.py: a fresh process instantiates the FMU, restores a serialized
state and steps the standard scenario from t_start to t_stop.

usage: state_worker.py UNZIPDIR STATE_FILE OUT_NPY T_START T_STOP
The outputs (scenarios.OUTPUTS, every 10 ms, t_start included) are saved with numpy.save.
"""

import sys
from pathlib import Path

import fmpy
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import scenarios  # noqa: E402
from jetpipe_fmu import initialize, make_slave, release, vr_map  # noqa: E402


def main(argv):
    unzipdir, state_file, out_file = argv[1], argv[2], argv[3]
    t_start, t_stop = float(argv[4]), float(argv[5])
    md = fmpy.read_model_description(str(Path(unzipdir) / "modelDescription.xml"))
    vrs = vr_map(md)
    fmu = make_slave(unzipdir, md)
    try:
        initialize(fmu, vrs, inputs=scenarios.held_input(0.0))
        state = fmu.deSerializeFMUstate(Path(state_file).read_bytes())
        fmu.setFMUstate(state)
        fmu.freeFMUstate(state)
        res = scenarios.step_scenario(fmu, vrs, 1e-2, t_start=t_start, t_stop=t_stop)
    finally:
        release(fmu)
    np.save(out_file, np.stack([res["time"]] + [res[n] for n in scenarios.OUTPUTS]))
    if fmu.log.messages:
        print(fmu.log.text())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
