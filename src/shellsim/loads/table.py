"""The base of every ``[[load]]`` table: what the registry, the plan and the plots read
from a load kind's deck table besides its own keys."""

from __future__ import annotations

from typing import Annotated, ClassVar

from pydantic import Field, field_validator

from ..table_types import Name, NonNegative, Positive, Section, tag_of

#: The largest Coulomb coefficient taken: wet tissue on tissue or a device slides at 0.01-0.5,
#: dry rubber on rubber at about 1-2; more is a typing mistake, not a surface.
MOST_FRICTION = 2.0


class LoadTable(Section):
    """A load (``value * curve(t)``) or a contact on a named set (``set`` and ``curve``
    are each table's own keys, with their defaults).

    DECK_KEY: the deck's list it goes in, ``load`` ([[load]]) or ``contact`` ([[contact]]);
    SET_KINDS: the kinds of set it acts on (:mod:`shellsim.deck.references` checks them);
    FEATURES: the plan's features (:mod:`shellsim.plan`) this table may use, the first
    unless :attr:`feature` says otherwise; QUANTITY: what ``value`` is, for plot axes:
    "stress" (force per area) or "load"; FILE_KEYS: its keys that name a file, a path
    relative to the deck (the deck's reading makes them absolute and checks that they
    exist)."""

    DECK_KEY: ClassVar[str] = "load"
    SET_KINDS: ClassVar[tuple[str, ...]]
    FEATURES: ClassVar[tuple[str, ...]]
    QUANTITY: ClassVar[str] = "load"
    FILE_KEYS: ClassVar[tuple[str, ...]] = ()

    @property
    def named_sets(self) -> dict[str, str]:
        """The sets the table names, by key (:mod:`shellsim.deck.references` checks them)."""
        return {"set": self.set}

    @property
    def feature(self) -> str:
        """The plan's feature this load uses."""
        return self.FEATURES[0]


class ContactTable(LoadTable):
    """A ``[[contact]]`` table: its ``name`` (history columns), the surface ``set`` whose
    faces touch, the penalty's scale and the Coulomb ``friction`` coefficient mu
    (regularised: the sliding force is mu times the contact force, or less where that
    would reverse the slip within a critical step, which is how sticking is held)."""

    name: Name
    set: Name = "all"
    penalty: Positive = 0.1
    friction: Annotated[NonNegative, Field(le=MOST_FRICTION)] = 0.0
    DECK_KEY: ClassVar[str] = "contact"
    SET_KINDS: ClassVar[tuple[str, ...]] = ("surface",)
    FEATURES: ClassVar[tuple[str, ...]] = ("contact",)
    #: Whether its kind slides with friction (has ``add_friction``; the registry checks):
    #: where it does not, a friction given is refused rather than ignored.
    FRICTION: ClassVar[bool] = True

    @field_validator("friction")
    @classmethod
    def _slides(cls, friction: float) -> float:
        if friction and not cls.FRICTION:
            raise ValueError(f"the {tag_of(cls)[1]!r} contact has no friction; leave friction out")
        return friction

    @property
    def moving_curve(self) -> str | None:
        """The curve that moves what the contact's surface meets (a tool pushed on), None
        where nothing moves: kinetic damping waits for it to stop."""
        return None

    @property
    def friction_summary(self) -> str:
        """The friction for ``check``'s line: '' when frictionless."""
        return f", friction {self.friction:g}" if self.friction else ""
