"""What an evaluation worker needs, imported and built once by the fork server that forks the workers.

:mod:`retrokit.benchmark.local` names this module as the fork server's
preload: each worker then starts with numpy, Gymnasium, the DSL's compiler
and the emulator host already imported, instead of importing them (about a
second of CPU) per level. It also builds what every level's env builds the
same way from retrokit's own files and the installed stable-retro wheel
(the DSL's parser, the data files' schema validators, the digests of the
shipped save states): a third of a second of CPU per level otherwise.
Nothing is read from the environment or the user's files, which a worker
reads when its level starts (a server may outlive many evaluations).
"""

from __future__ import annotations

import retrokit.benchmark.agents
import retrokit.benchmark.jerk
import retrokit.benchmark.level
import retrokit.data.resolve
import retrokit.dsl.compiler
import retrokit.envs.env
import retrokit.host.emulator  # noqa: F401
from retrokit.data import schema, statecheck
from retrokit.dsl import parser

parser.warm()
schema.warm()
statecheck.warm()
