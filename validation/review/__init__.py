"""What a person reviews: the summary tables, Rerun recordings and plots.

Used by ``artic validate``, the campaign and ``artic dock`` alike.

- :mod:`~artic.validation.review.tables`: the paper's Tables 2 and 3 with
  intervals, paired comparisons, the excess over the floor, pooling over trucks;
- :mod:`~artic.validation.review.recording`: Rerun recordings, one per manoeuvre
  and one per campaign (artic's only module that imports rerun);
- :mod:`~artic.validation.review.plantshape`: the plant's bodies and geoms, as the
  recordings draw them;
- :mod:`~artic.validation.review.plots`: static plots of a manoeuvre;
- :mod:`~artic.validation.review.frequency`: gain and phase of the yaw rates and
  the articulation against the steering, each model against the truth;
- :mod:`~artic.validation.review.frequencystudy`: the swept sine through the truth and
  each model, and their frequency responses.
"""
