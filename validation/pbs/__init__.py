"""Low-speed performance measures: swept path, swings, off-tracking, friction demand (artic pbs).

The measures the performance-based standards of heavy vehicles take in a
walking-pace turn, each in its own module, from the motion alone:
standards.py (the manoeuvres, limits and levels, and the documents they
come from), paths.py (the prescribed tangent-arc-tangent paths and their
path coordinates), motion.py (the units' points from the observed motion and
the outline), sweep.py (the low-speed swept path), swing.py (frontal and tail
swing), offtracking.py (J695's steady and the FHWA turn's off-tracking),
friction.py (steer-tyre friction demand), driver.py (the path-following
driver), run.py (the manoeuvres on one model and its measures), fromlog.py
(the measures of a measured run, for artic validate), tables.py (the tables
and the PBS levels), figure.py (the swept paths drawn), command.py (artic pbs),
trucks.py (each model's error per truck in the campaign, and over trucks).
"""
