"""Reference numbers the tests and studies compare with, in one place (SI units).

Sources: Khosravani (2014), thesis Tables 4.1, 4.5, 5.3 and Fig. 5.5; Kim, T.-H. (2001),
Moisture-induced tensile strength and cohesion in sand, PhD thesis, University of Colorado at
Boulder, through the thesis's Table 4.5 (direct tension of F-75 sand); docs/physics.md 'Errata'
for the Chapter 4 surface tension. ``comparison_packing`` names the regular packing of thesis
Ch. 4 a sample of a given void ratio is compared with (pendular.procedures.tension,
pendular.studies.chapter4).
"""

#: Surface tension of Chapter 4 [N/m] (the printed "74 µN/m" is 0.074 N/m, docs/physics.md
#: 'Errata'); Chapter 5 uses capillary.SURFACE_TENSION = 0.073.
CHAPTER4_SURFACE_TENSION = 0.074
#: Specific gravity of the grains (quartz sand), Gs.
SPECIFIC_GRAVITY = 2.65

#: Thesis Table 4.1 as printed: l', porosity, Fx, Fy, Fz, anisotropy a (BCC packings).
TABLE_4_1_PRINTED = [
    (2.1, 0.312, 0.362, 0.362, 0.276, -0.22),
    (2.2, 0.318, 0.335, 0.335, 0.330, -0.012),
    (2.3094, 0.320, 0.333, 0.333, 0.333, 0.0),
    (2.4, 0.318, 0.320, 0.320, 0.360, 0.10),
    (2.5, 0.313, 0.305, 0.305, 0.390, 0.21),
    (2.6, 0.303, 0.289, 0.289, 0.422, 0.33),
    (2.7, 0.288, 0.272, 0.272, 0.456, 0.46),
]

#: Kim (2001), thesis Table 4.5: void ratio, gravimetric water content, tensile strength [Pa].
KIM_2001 = [
    (0.72, 0.0047, 412.61), (0.72, 0.0104, 584.53), (0.72, 0.0211, 699.14),
    (0.58, 0.0043, 492.84), (0.58, 0.0104, 716.33), (0.58, 0.0201, 962.75),
]
#: A grading of Kim's F-75 sand ((diameter [m], percent passing by mass), pendular.dem.grading): the
#: thesis (§4.4.1.2) gives Kim's uniformity Cu = 2 and mean radius 0.11 mm (ASTM D422, read as
#: D50 = 0.22 mm); no sieve curve is in our sources, so the curve is linear in log d from
#: 0.11 to 0.44 mm, whose D50 is 0.22 mm and Cu = D60 / D10 = 4^0.5 = 2.
KIM_F75_GRADING = ((0.11e-3, 0.0), (0.44e-3, 100.0))
#: F-75 sand mean radius [m] and the thesis's roughness H/R of its grains.
KIM_RADIUS = 0.11e-3
KIM_SEPARATION = 0.09
#: Regular packing compared with each of Kim's void ratios: (kind, label).
KIM_PACKINGS = {0.72: ("bcc", "isotropic BCC"), 0.58: ("fcp", "FCP")}
#: Void ratio from which a sample is compared with Kim's loose packing (docs/chapter4.md).
KIM_LOOSE_FROM = 0.65


def comparison_packing(void_ratio: float) -> tuple[str, str]:
    """(kind, label) of the regular packing a sample of this void ratio is compared with:
    isotropic BCC for e >= KIM_LOOSE_FROM, FCP below (docs/chapter4.md)."""
    return KIM_PACKINGS[0.72] if void_ratio >= KIM_LOOSE_FROM else KIM_PACKINGS[0.58]

#: Thesis Table 5.3: axial stress at peak [Pa], keyed (suction [Pa], lateral stress [Pa]).
TABLE_5_3 = {
    (0, 250): 591, (0, 500): 1207, (0, 750): 1843, (0, 1000): 2480,
    (15000, 250): 5388, (15000, 500): 6345, (15000, 750): 7201, (15000, 1000): 8018,
    (30000, 250): 5748, (30000, 500): 6593, (30000, 750): 7426, (30000, 1000): 8329,
    (300000, 250): 6380, (300000, 750): 8289,
}
#: Thesis Fig. 5.5: degree of saturation [-] by suction [Pa].
FIG_5_5 = {15000: 0.055, 30000: 0.022, 300000: 0.0005}
#: Thesis dry friction angle [deg].
DRY_FRICTION_DEG = 25.0
