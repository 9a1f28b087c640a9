"""What the cargo box carries: the product's temperature band — the legal limits of its class
— and how its temperature follows the box air.

Classes and their limits:

* ``frozen``: quick-frozen foodstuffs at −18 °C or colder, brief rises of at most 3 °C in
  transport (Council Directive 89/108/EEC, art. 5 and Annex; ATP Annex 2: "other deep-frozen
  foodstuffs" −18 °C); "brief" the rules leave open — a rise may last
  :data:`BRIEF_RISE_MINUTES` at a time.
* ``ice-cream``: −20 °C (ATP Annex 2), the same brief rise of 3 °C (89/108/EEC).
* the chilled classes of ATP Annex 3 (highest temperature of the foodstuff in carriage):
  ``chilled-minced-meat`` +2 °C, ``chilled-offal`` +3 °C, ``chilled-poultry`` +4 °C,
  ``chilled-dairy`` +6 °C, ``raw-milk`` +6 °C, ``chilled-red-meat`` +7 °C; no rise allowed.
  Chilled goods must not freeze: meat from about −1.5 °C (ASHRAE Handbook — Refrigeration
  (2018) ch. 19, initial freezing points of foods: beef −1.7 °C, poultry −1.5 °C) — the floor is
  −1 °C —, milk at −0.5 °C — the floor is 0 °C.

Goods are loaded, and the air is held, at the band's middle unless the request says otherwise
(the frozen classes' floor is the coldest a small van's unit reaches, −30 °C: their middle is
−24 °C, −25 °C for ice cream, usual reefer settings).
"""

from __future__ import annotations

import sys
from typing import Annotated, Literal

from pydantic import AfterValidator, Discriminator, Field, Tag, ValidationInfo, field_validator

from core.params.base import BRANCH_TAG, Params

#: How long a brief rise of the goods above their band may last [min] unless the product says:
#: the rules name no length (89/108/EEC art. 5: "brief upwards fluctuations"), so a stop's door
#: opening and the recovery after it — half an hour.
BRIEF_RISE_MINUTES = 30.0


def _not_subnormal(value: float) -> float:
    if value != 0 and abs(value) < sys.float_info.min:
        raise ValueError(f"{value!r} is a subnormal number: send 0 or a temperature that means one")
    return value


#: A temperature [°C] that is not a subnormal number (its digits are noise, not a reading).
Celsius = Annotated[float, AfterValidator(_not_subnormal)]


class ProductBand(Params):
    """The product's temperature band: what the rules allow the goods themselves (not the
    air) to be."""

    min_c: Celsius = Field(
        ...,
        ge=-60,
        le=30,
        description="Coldest the product may be [°C] (chilled goods must not freeze).",
    )
    max_c: Celsius = Field(
        ..., ge=-60, le=30, description="Warmest the product may be [°C]; above min_c."
    )
    excursion_c: Celsius = Field(
        0.0,
        ge=0,
        le=10,
        description="A brief rise above max_c the rules tolerate in transport [K] "
        "(quick-frozen food: 3 K, Directive 89/108/EEC); the cold chain breaks beyond it.",
    )
    excursion_minutes: float = Field(
        BRIEF_RISE_MINUTES,
        ge=0,
        le=1440,
        description="How long one rise above max_c (within excursion_c) may last [min]. "
        "Directive 89/108/EEC (art. 5) allows quick-frozen food 'brief upwards fluctuations' "
        "of at most 3 °C in distribution without saying how brief; coldroute takes 30 "
        "minutes by default — a door opening at a stop and the recovery after it, not an "
        "afternoon. A longer rise breaks the cold chain.",
    )

    @field_validator("max_c")
    @classmethod
    def _above_floor(cls, value: float, info: ValidationInfo) -> float:
        if "min_c" in info.data and value <= info.data["min_c"]:
            raise ValueError("max_c must be above min_c")
        return value

    @property
    def middle_c(self) -> float:
        return 0.5 * (self.min_c + self.max_c)


ProductClass = Literal[
    "frozen",
    "ice-cream",
    "chilled-minced-meat",
    "chilled-offal",
    "chilled-poultry",
    "chilled-dairy",
    "raw-milk",
    "chilled-red-meat",
]


def _product_branch(value: object) -> str:
    return BRANCH_TAG + ("class" if isinstance(value, str) else "band")


#: A product: its class's name, or its band.
Product = Annotated[
    Annotated[ProductClass, Tag(BRANCH_TAG + "class")]
    | Annotated[ProductBand, Tag(BRANCH_TAG + "band")],
    Discriminator(_product_branch),
]

#: Floor of the frozen classes [°C]: none in law; the coldest a small van's unit reaches
#: (Thermo King and Carrier van units are rated to about −30 °C).
FROZEN_FLOOR_C = -30.0
#: Floors of the chilled classes [°C]: meat from about −1.5 °C, milk −0.5 °C (module docstring).
MEAT_FLOOR_C = -1.0
MILK_FLOOR_C = 0.0


def _band(max_c: float, min_c: float, excursion_c: float = 0.0) -> ProductBand:
    return ProductBand(min_c=min_c, max_c=max_c, excursion_c=excursion_c)


#: Each class's band.
PRODUCT_CLASSES: dict[str, ProductBand] = {
    "frozen": _band(-18.0, FROZEN_FLOOR_C, 3.0),
    "ice-cream": _band(-20.0, FROZEN_FLOOR_C, 3.0),
    "chilled-minced-meat": _band(2.0, MEAT_FLOOR_C),
    "chilled-offal": _band(3.0, MEAT_FLOOR_C),
    "chilled-poultry": _band(4.0, MEAT_FLOOR_C),
    "chilled-dairy": _band(6.0, MILK_FLOOR_C),
    "raw-milk": _band(6.0, MILK_FLOOR_C),
    "chilled-red-meat": _band(7.0, MEAT_FLOOR_C),
}


def product_band(product: ProductClass | ProductBand) -> ProductBand:
    """The band of a class (by name) or the band itself."""
    return product if isinstance(product, ProductBand) else PRODUCT_CLASSES[product]
