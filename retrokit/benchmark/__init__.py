"""The benchmark protocol: levels, agents, the runner, reports and plots.

A benchmark (:mod:`.definition`) is data: its levels split into train and
test, the env rules and the budget of timesteps per level. An agent
(:mod:`.agents`, :mod:`.jerk`) plays one level's env until the budget is
spent, watched by a :class:`~.monitor.Monitor` that counts timesteps and
records episodes. :mod:`.level` runs one level as a stream of messages, which
the local processes (:mod:`.local`) or Ray (:mod:`.ray_backend`) carry back to
:mod:`.evaluation`; that writes the run folder (:mod:`.rundir`), the summary
and report (:mod:`.report`) and the plots (:mod:`.plots`), beside the paper's
scores (:mod:`.paper`). ``retrokit evaluate`` is the command line.
"""

from __future__ import annotations

from retrokit.lazy import lazy_names

__getattr__ = lazy_names(__name__)  # its submodules, on first use: retrokit.benchmark.<module>
