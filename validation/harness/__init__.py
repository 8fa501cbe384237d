"""The closed-loop harness: drives any model from a log with the reversing feedback.

- :mod:`~artic.validation.harness.loop`: the closed loop, eqs. (5)-(7): a log's
  inputs, any model driven through them, the model's run;
- :mod:`~artic.validation.harness.feedback`: its steering law, one function every
  loop runs; :mod:`~artic.validation.harness.reducedloop`: the loop for KIN and
  the STM, compiled by numba;
- :mod:`~artic.validation.harness.reversing`: when the feedback is on (reversing
  decided with hysteresis on the speed) and its weight, handed over in ramps;
- :mod:`~artic.validation.harness.batch`: many logs through the harness at once;
- :mod:`~artic.validation.harness.simulate`: open-loop simulation of a manoeuvre,
  and a driver who steers the articulation onto a reference, through a
  manoeuvre's inputs (:mod:`artic.validation.logs.profile`);
- :mod:`~artic.validation.harness.plantnotes`: what the plant had to limit during
  a run, collected per run instead of printed.

The steering map of eq. (3) is the vehicle's (:mod:`artic.mjcf.steering`); steering
from the measured yaw rate is a log's (:mod:`artic.validation.logs.yawsteer`).
"""
