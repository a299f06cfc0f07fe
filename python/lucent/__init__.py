"""lucent from Python: materials, models, measurement and fits (units: mm, mm^-1).

The compiled part is lucent._lucent; everything is re-exported here. Bad input raises
lucent.Error (a ValueError) with the one-line message the CLI prints.
"""
from ._lucent import *  # noqa: F401,F403
from ._lucent import Error, Material, Profile, FitResult  # noqa: F401

__all__ = [name for name in dir() if not name.startswith("_")]
