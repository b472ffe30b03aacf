"""The glass plant's numbers: stability, the rules a capacity and a drawing follow, membrane stress.

Modules, each a plain function of a valid :class:`~engine.model.design.Design` (mm, g, ml, MPa):

* :mod:`.mass` — masses and centres of gravity of the glass, the liquid (upright and with its
  free surface level in a tilted bottle), the closure and the labels.
* :mod:`.clip` — exact half-plane clips of the cross-sections (what a tilted liquid keeps).
* :mod:`.stability` — the standing ring and the tip angle of each state (empty, filled, brimful).
* :mod:`.membrane` — hoop and meridional membrane stress along the profile under a proof
  pressure, with the places membrane theory does not hold marked instead of given a number.
* :mod:`.thickness` — where an outline bottle's sloped walls leave the glass thinner along its
  normal than the wall.
* :mod:`.rules` — the capacity band of 75/107/EEC, the marking, the dimension tolerances of
  ISO 9058 (with the rule each comes from).
* :mod:`.sheet` — :func:`~.sheet.plant_numbers`, the one dict every front end shows
  (``glassbench info --json``, the trade panel, the drawing, batches).

The derivations and their assumptions are in ``docs/PLANT.md``.
"""
