"""The contract's array and field names (docs/CONTRACT.md), read from Filters/Core/Contract.h, the one
place they are written: featuremesh.names.Label is "Label"."""
import os
import re

_CONTRACT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "Filters", "Core", "Contract.h")

with open(_CONTRACT) as _f:
    _NAMES = dict(re.findall(r'constexpr const char\* (\w+) = "([^"]*)";', _f.read()))
globals().update(_NAMES)


def all_names():
    """{C++ constant: array name} of every name in Contract.h."""
    return dict(_NAMES)
