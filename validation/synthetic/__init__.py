"""The synthetic measured campaign: what is driven, by whom, and how it is measured.

- :mod:`~artic.validation.synthetic.testmatrix`: the paper's test matrix over both loads;
- :mod:`~artic.validation.synthetic.manoeuvres`: open-loop steering and speed profiles;
- :mod:`~artic.validation.synthetic.driver`: the docking and parking driver, the truth's own
  (preview on the dock's line, nothing of the harness's law);
- :mod:`~artic.validation.synthetic.sensors`: RTK GNSS, inertial unit and CAN models;
- :mod:`~artic.validation.synthetic.truth`: the truth configurations, drawn from the seed;
- :mod:`~artic.validation.synthetic.yardtruth`: the independent truth, a vehicle with its
  own skeleton (:mod:`~artic.validation.synthetic.yardbuild`), tyres
  (:mod:`~artic.validation.synthetic.yardtyres`) and loop (``_truth_c.c``), sharing no
  code with the plant;
- :mod:`~artic.validation.synthetic.truthplant`: the truths on the plant's skeleton (the
  structural and legacy ones, and the independent truth of the release before with
  :mod:`~artic.validation.synthetic.tmeasy` tyres and :mod:`~artic.validation.synthetic.column`);
- :mod:`~artic.validation.synthetic.truthmodel`: the model a truth configuration drives
  and its driver's seat, without loading the plant for the yard truth;
- :mod:`~artic.validation.synthetic.actuation`: the truth's driver on the steering wheel
  and the pedals;
- :mod:`~artic.validation.synthetic.generate`: ``artic logs generate``, the matrix
  driven on the truth and exported as measured files.
"""
