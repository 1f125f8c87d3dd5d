"""Each load kind keeps its role's contract, checked as the registry imports it: a hook
left out or misspelt, half a pair, a table without what `check` prints, or a friction
the kind cannot apply each fail there by name; every shipped kind passes."""

from __future__ import annotations

from types import ModuleType
import pytest

from shellsim.deck import parse_deck
from shellsim.errors import DeckError
from shellsim.loads import KINDS, ROLE, rigid_tool, shell_contact
from shellsim.loads.contract import check_kind
from shellsim.loads.table import ContactTable

from .conftest import deck_text


def _copy(kind: ModuleType, drop: tuple[str, ...] = (), **more) -> ModuleType:
    """A module with ``kind``'s names but ``drop``, and ``more``."""
    copy = ModuleType(kind.__name__)
    vars(copy).update({k: v for k, v in vars(kind).items() if k not in drop} | more)
    return copy


def test_every_shipped_kind_keeps_its_role_s_contract():
    assert {ROLE[kind] for kind in KINDS} == {"load", "contact", "cable"}
    assert all(check_kind(kind) == ROLE[kind] for kind in KINDS)


@pytest.mark.parametrize(("drop", "more", "said"), [
    (("item_gaps",), {}, "lacks item_gaps"),
    (("item_gaps",), {"item_gap": print}, "has 'item_gap', which no role uses: is it the hook 'item_gaps' misspelt?"),
    (("farthest_moved",), {}, "has deepest without farthest_moved"),
])
def test_a_contact_kind_with_a_hook_left_out_or_misspelt_fails_by_name(drop, more, said):
    with pytest.raises(TypeError, match=f"load kind shellsim.loads.shell_contact \\(a contact\\) .*{said[:30]}"):
        check_kind(_copy(shell_contact, drop, **more))


def test_a_contact_table_without_a_summary_or_with_a_friction_its_kind_cannot_apply_fails():
    class Bare(ContactTable):
        type: str = "bare"

    with pytest.raises(TypeError, match="its table Bare lacks summary, which shellsim check reads"):
        check_kind(_copy(rigid_tool, TABLES=(Bare,)))
    with pytest.raises(TypeError, match="takes a friction, which the kind has no add_friction for"):
        check_kind(_copy(rigid_tool, ("add_friction",)))
    with pytest.raises(TypeError, match="has friction_couplings without add_friction"):
        check_kind(_copy(shell_contact, ("add_friction",)))


def test_a_friction_on_a_contact_without_friction_is_refused_not_ignored(monkeypatch):
    """A table declaring FRICTION = False refuses friction = 0.3 with its key named; the
    shipped tool contact, which has friction, takes it."""
    table = rigid_tool.RigidTool
    tool = ('[[contact]]\ntype = "rigid_tool"\nname = "plate"\nshape = "plane"\npoint = [0.0, 0.0, -0.1]\n'
            'normal = [0.0, 0.0, 1.0]\nfriction = 0.3\n')
    text = deck_text('builder = "rectangle"\nlength = 2.0\nwidth = 1.0', tool).replace(
        "[solver]\n", '[solver]\nmethod = "explicit"\n')
    assert parse_deck(text).contact[0].friction == 0.3
    monkeypatch.setattr(table, "FRICTION", False)
    with pytest.raises(DeckError, match=r"contact\[0\].friction.*the 'rigid_tool' contact has no friction"):
        parse_deck(text)
