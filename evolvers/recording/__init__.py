"""The run folder every driver writes and the study reads.

* :mod:`~evolvers.recording.recorder` - :class:`~evolvers.recording.recorder.RunRecorder`
  (config, log, hall of fame, atomic checkpoints, best designs, figures, progress,
  Ctrl-C), the folder's config and notes;
* :mod:`~evolvers.recording.rows` - one log row per generation (statistics of every
  recorded metric, the columns a study report reads) and a population as plain data.

Uses :mod:`evolvers.operators` and :mod:`evolvers.evaluation`; imports no driver.
"""
