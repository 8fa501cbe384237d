"""The synthetic measured campaign: what is driven, by whom, and how it is measured.

- :mod:`~artic.validation.synthetic.testmatrix`: the paper's test matrix over both loads;
- :mod:`~artic.validation.synthetic.manoeuvres`: open-loop steering and speed profiles;
- :mod:`~artic.validation.synthetic.driver`: the docking and parking driver;
- :mod:`~artic.validation.synthetic.sensors`: RTK GNSS, inertial unit and CAN models;
- :mod:`~artic.validation.synthetic.generate`: ``artic logs generate``, the matrix
  driven on the plant in its truth configuration and exported as measured files.
"""
