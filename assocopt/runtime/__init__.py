"""Runtime helpers every layer may use: the error types (:mod:`.errors`), progress on
a terminal (:mod:`.progress`) and the watch that stops a worker when its parent dies
(:mod:`.parent_watch`).

May import: nothing of assocopt (the standard library and tqdm only).
"""
