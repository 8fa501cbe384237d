"""The synthetic measured campaign: what is driven, by whom, and how it is measured.

- :mod:`~artic.validation.synthetic.testmatrix`: the paper's test matrix over both loads;
- :mod:`~artic.validation.synthetic.manoeuvres`: open-loop steering and speed profiles;
- :mod:`~artic.validation.synthetic.driver`: the docking and parking driver;
- :mod:`~artic.validation.synthetic.sensors`: RTK GNSS, inertial unit and CAN models;
- :mod:`~artic.validation.synthetic.truth`: the truth configurations, drawn from the seed;
- :mod:`~artic.validation.synthetic.truthplant`: the independent truth's own model, with
  :mod:`~artic.validation.synthetic.tmeasy` tyres (compiled in ``_truth_c.c``, loaded by
  :mod:`~artic.validation.synthetic.truthc`) and :mod:`~artic.validation.synthetic.column`,
  its steering;
- :mod:`~artic.validation.synthetic.actuation`: the truth's driver on the steering wheel
  and the pedals;
- :mod:`~artic.validation.synthetic.generate`: ``artic logs generate``, the matrix
  driven on the truth and exported as measured files.
"""
