"""What an evaluation worker needs, imported once by the fork server that forks the workers.

:mod:`retrokit.benchmark.local` names this module as the fork server's
preload: each worker then starts with numpy, Gymnasium, the DSL's compiler
and the emulator host already imported, instead of importing them (about a
second of CPU) per level. Only modules are imported here; nothing is read
from the environment or the user's files, which a worker reads when its
level starts (a server may outlive many evaluations).
"""

from __future__ import annotations

import retrokit.benchmark.agents
import retrokit.benchmark.jerk
import retrokit.benchmark.level
import retrokit.data.resolve
import retrokit.dsl.compiler
import retrokit.envs.env
import retrokit.host.emulator  # noqa: F401
