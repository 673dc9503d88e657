"""retrokit's scenario language: rewards and done conditions as checked, compiled expressions.

The language is documented in ``docs/scenarios.md``. The pipeline:
:mod:`~retrokit.dsl.document` (YAML) or :mod:`~retrokit.dsl.gymretro`
(scenario.json) builds a :class:`~retrokit.dsl.spec.ScenarioSpec`;
:mod:`~retrokit.dsl.parser` parses its expressions with lark;
:mod:`~retrokit.dsl.check`, :mod:`~retrokit.dsl.graph` and
:mod:`~retrokit.dsl.typecheck` check them; :mod:`~retrokit.dsl.codegen` and
:mod:`~retrokit.dsl.compiler` turn them into Python functions. Use
:func:`retrokit.dsl.scenario.load_scenario` rather than these modules.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from retrokit.lazy import lazy_names

if TYPE_CHECKING:
    from retrokit.dsl.gymretro import convert_scenario_json

__all__ = ["convert_scenario_json"]

# Its submodules too, on first use: the compiler's imports (lark) wait until a scenario needs them.
__getattr__ = lazy_names(__name__, {"convert_scenario_json": "retrokit.dsl.gymretro"})
