"""What a kind of :mod:`shellsim.loads` must and may provide, by its role, checked when
the registry imports it: a hook left out, or one misspelt, fails there with its name,
not in the middle of a run or of ``shellsim check``.

A kind's role is its deck tables' ``DECK_KEY``: a ``load``, a ``contact`` or a ``cable``.
The hooks are described in :mod:`shellsim.loads`; here is which of them each role needs.
"""

from __future__ import annotations

import difflib
from types import ModuleType

#: Every kind's: its deck tables and how one becomes its loads.
EVERY = ("TABLES", "build")
#: A kind with kernels of its own (a ``Bundle``) adds its forces.
CARRYING = ("Bundle", "add_forces")
#: By role: (the hooks it must have beyond EVERY, those it may have).
ROLES = {
    "load": ((), ("Bundle", "add_forces", "empty", "joined", "add_tangent", "couplings")),
    "contact": ((*CARRYING, "calibrate", "step_share", "item_forces", "item_energies", "item_gaps", "FORCE_TOTAL",
                 "SIDES"),
                ("add_tangent", "add_friction", "friction_couplings", "deepest", "farthest_moved", "couplings", "empty",
                 "overlaps_at_rest", "hold_pairs", "pairs")),
    "cable": ((*CARRYING, "extend_mesh", "add_masses", "critical_step"), ("add_tangent", "couplings", "empty")),
}
#: Hooks that come together or not at all.
PAIRS = (("deepest", "farthest_moved"), ("hold_pairs", "pairs"))
#: What a role's deck table must have beyond its keys: the line ``shellsim check`` prints.
TABLE_HOOKS = {"load": (), "contact": ("summary",), "cable": ("summary", "elements", "declared_sets")}
#: How close a name of the kind's must be to a hook it lacks to be taken for a misspelling.
MISSPELT = 0.85


def role_of(kind: ModuleType) -> str:
    """The role of ``kind``: the deck key its tables share. TypeError where they do not."""
    keys = {table.DECK_KEY for table in getattr(kind, "TABLES", ())}
    if len(keys) != 1 or not keys <= set(ROLES):
        raise TypeError(f"load kind {kind.__name__}: its TABLES must be tables of one role ({', '.join(ROLES)}); "
                        f"they are {sorted(keys) or 'none'}")
    return keys.pop()


def check_kind(kind: ModuleType) -> str:
    """Raise TypeError naming the hook where ``kind`` breaks its role's contract: a hook
    it must have and lacks, a name that looks like a misspelt hook, a pair of hooks half
    given, or a table without what ``check`` reads. Returns the role."""
    role = role_of(kind)
    required, optional = ROLES[role]
    required = EVERY + required + (CARRYING if hasattr(kind, "Bundle") else ())
    where = f"load kind {kind.__name__} (a {role})"
    names = [name for name in vars(kind) if not name.startswith("_")]
    for hook in dict.fromkeys((*required, *optional)):
        close = difflib.get_close_matches(hook, names, n=1, cutoff=MISSPELT)
        if not hasattr(kind, hook) and close:
            raise TypeError(f"{where} has {close[0]!r}, which no role uses: is it the hook {hook!r} misspelt?")
    missing = [hook for hook in dict.fromkeys(required) if not hasattr(kind, hook)]
    if missing:
        raise TypeError(f"{where} lacks {', '.join(missing)}: see shellsim.loads for what each does")
    for pair in PAIRS:
        given = [hook for hook in pair if hasattr(kind, hook)]
        if given and len(given) != len(pair):
            raise TypeError(f"{where} has {given[0]} without {', '.join(h for h in pair if h not in given)}: "
                            "they come together")
    if hasattr(kind, "friction_couplings") and not hasattr(kind, "add_friction"):
        raise TypeError(f"{where} has friction_couplings without add_friction: the derivative of a friction it "
                        "does not apply")
    for table in kind.TABLES:
        absent = [hook for hook in TABLE_HOOKS[role] if not hasattr(table, hook)]
        if absent:
            raise TypeError(f"{where}: its table {table.__name__} lacks {', '.join(absent)}, which shellsim check reads")
        if getattr(table, "FRICTION", False) and not hasattr(kind, "add_friction"):
            raise TypeError(f"{where}: its table {table.__name__} takes a friction, which the kind has no add_friction "
                            "for: give the table FRICTION = False, so a friction given is refused")
    return role
