"""The slots every sensor an estimator reads (`imu`, `mocap`, `gnss`: issue 33) keeps first in
its memory (one UAV's, `SENSOR_MODELS`' `memory`): its latest output and when it came, which
the estimators (`multilift_sim.estimators`) read. Such a sensor leaves what the controllers
receive alone (they read the estimate, or the state without an estimator)."""

ARRIVED = 0      # the control tick its latest output arrived at (-1: none yet)
TAKEN = 1        # the control tick that output was sampled at (its latency: ARRIVED - TAKEN)
OUTPUT = 2       # the output itself, its model's slots (the model's OUTPUT_* names them)
