"""Each person's colour, by identity: the overlay and the recording agree, so a person
looks the same in the annotated video and in rerun."""

from __future__ import annotations

# Told apart at a glance (RGB), none of them a risk colour (green, yellow, red).
PERSON_COLOURS = (
    (80, 220, 255), (255, 140, 40), (190, 110, 255), (255, 255, 120),
    (120, 255, 200), (255, 120, 180), (150, 190, 255), (210, 170, 120),
)  # fmt: skip


# Their names, so a text (a recording's warning event) points at the box of that colour.
COLOUR_NAMES = ("sky blue", "orange", "violet", "pale yellow", "mint", "pink", "light blue",
                "tan")  # fmt: skip


def person_colour(person_id: int) -> tuple[int, int, int]:
    return PERSON_COLOURS[person_id % len(PERSON_COLOURS)]


def person_colour_name(person_id: int) -> str:
    """The name of `person_colour(person_id)`."""
    return COLOUR_NAMES[person_id % len(COLOUR_NAMES)]
