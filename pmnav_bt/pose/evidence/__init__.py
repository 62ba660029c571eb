"""What the corridor belief weighs its hypotheses by, one kind of evidence a module.

Each kind says what it models and owns its probabilities; each adds log-likelihoods to
the belief's per-hypothesis log-weights (``logw``, in place, in the order the belief
calls them: the sums are kept bit for bit as they were).

- ``signs``: the signs read at a look round, where each was seen; signs the map says are
  readable but were not read (missed); signs read where the map says none can be
  (misread or spurious).
- ``floor``: where the map's corridors are: the robot inside a wall (off the corridors),
  a drive blocked where the corridor goes on, walls close ahead and free floor along each
  view in depth (at a look round and along a drive).
- ``doors``: doors seen along the walls, or map doors in view not seen.
- ``prior``: an earlier estimate of the pose.
"""
