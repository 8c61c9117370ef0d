"""Work limits shared by the command line and the API: beyond them a call refuses before it
allocates anything and names what lifts the limit (``--allow-large`` on the command line,
``allow_large=True`` in the API). No imports: the command line reads them at start-up."""

#: fields (chief rays per plane), radii or rays of one request
MAX_FIELDS = 100_000
#: rays of one ray fan or one field's spot diagram (pupil samples: ``--n``, or the rays that
#: ``--pattern`` and ``--rings`` make)
MAX_SAMPLES = 1_000_000
#: Monte Carlo instances of one tolerance run
MAX_INSTANCES = 1_000_000
