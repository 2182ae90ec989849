"""The warning horizon the pipeline predicts to unless told otherwise: the paper's 1 s.

The one definition of it: the pipeline's configuration, `monopic video --horizon`, the
trees' training, the replay of the authors' logs (recorded at this horizon), the people
tracker's urgency and the simulator's small-scale scenarios (sim.scenario.presets) read it.
"""

from __future__ import annotations

HORIZON_S = 1.0  # s
