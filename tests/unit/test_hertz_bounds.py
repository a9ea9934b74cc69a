"""Tests of the bounds on Young's modulus of a laboratory test with Hertz–Mindlin contacts
(pendular.procedures.preparation.hertz_overlap, pendular.procedures.laboratory.
check_hertz_equilibria): the overlap against Hertz's force solved numerically, grain moduli
the linear law's rule refused now accepted, and the refusals that remain naming --young and
its valid range. Configurations only: nothing runs."""

import math

import pytest
import scipy.optimize

from pendular.dem.hertz_mindlin import effective_modulus
from pendular.procedures.feasibility import check_feasible
from pendular.procedures.preparation import (PEAK_FORCE_OVER_STRESS, hertz_overlap,
    hertz_stress_over_young)
from pendular.procedures.registry import config_from_options

HM = {"contact": "hertz-mindlin"}


@pytest.mark.parametrize("stress, young, poisson", [(5e3, 1e9, 0.3), (750.0, 7e10, 0.22),
                                                    (2e4, 1e6, 0.0)])
def test_the_overlap_is_hertz_force_solved_for_the_most_loaded_contact(stress, young, poisson):
    """delta / R from F = (4/3) E* sqrt(R*) delta^1.5 = PEAK_FORCE_OVER_STRESS stress R^2,
    solved by root finding with the engine's own E* of two equal grains, and back."""
    radius = 2.4e-5
    force = PEAK_FORCE_OVER_STRESS * stress * radius ** 2
    modulus = effective_modulus(young, poisson, young, poisson)
    overlap = scipy.optimize.brentq(
        lambda d: 4.0 / 3.0 * modulus * math.sqrt(radius / 2.0) * d ** 1.5 - force,
        0.0, radius, xtol=1e-30, rtol=1e-14)
    assert hertz_overlap(stress, young, poisson) == pytest.approx(overlap / radius, rel=1e-10)
    assert hertz_stress_over_young(overlap / radius, poisson) == pytest.approx(
        stress / young, rel=1e-10)


def feasible(command, **options):
    """check_feasible of the configuration of ``command`` with ``options``."""
    check_feasible(config_from_options(command, options))


def test_a_grain_modulus_the_linear_rule_refuses_is_accepted_with_hertz_mindlin():
    with pytest.raises(ValueError, match=r"^young = 1e\+09 Pa is outside the valid range "
                       r"\(0, 5e\+07\] Pa for the preparation at prep_stress = 5000 Pa"):
        feasible("triaxial", young=1e9)
    feasible("triaxial", young=1e9, **HM)
    feasible("isotropic", young=1e9, particles=300, **HM)


def test_glass_is_refused_by_the_step_count_then_by_the_growth_naming_young():
    with pytest.raises(ValueError, match=r"^the shear would take .* lower --young"):
        feasible("triaxial", young=7e10, **HM)
    with pytest.raises(ValueError, match=r"^--young = 7e\+10 Pa is outside the valid range "
                       r"\(0, 3\.4\d*e\+09\] Pa of Hertz–Mindlin grains .* prep_stress = "
                       "5000 Pa"):
        feasible("triaxial", young=7e10, max_strain=0.01, **HM)
    check_feasible(config_from_options("triaxial", {"young": 7e10, "max_strain": 0.01, **HM}),
                   force=True)


def test_the_bound_of_the_growth_is_where_its_overlap_is_the_linear_laws():
    """At the largest accepted young the most loaded Hertz contact overlaps by as much as a
    linear one at the linear law's largest young (8 x 1e-4 of the radius)."""
    feasible("isotropic", young=3.4e9, particles=300, **HM)
    with pytest.raises(ValueError, match="^--young = 3.5e"):
        feasible("isotropic", young=3.5e9, particles=300, **HM)
    assert hertz_overlap(5e3, 3.4125e9, 0.3) == pytest.approx(8e-4, rel=1e-3)


def test_a_low_confining_stress_is_refused_naming_young_and_its_range():
    with pytest.raises(ValueError, match=r"^--young = 1e\+09 Pa is outside the valid range "
                       r"\(0, 6\.\d*e\+08\] Pa .* at confining = 10 Pa"):
        feasible("isotropic", young=1e9, confining=10.0, particles=300, **HM)


def test_too_soft_grains_are_refused_naming_young_and_its_range():
    with pytest.raises(ValueError, match=r"prep_stress = 5000 Pa is outside the valid range "
                       r"\[0, 2000\] Pa for Hertz–Mindlin grains of --young 100000 Pa: .* give "
                       r"--young in \[250000, inf\) Pa"):
        feasible("triaxial", young=1e5, **HM)


def test_an_swcc_checks_hertz_mindlin_grains_by_their_overlaps():
    """The SWCC's servoed walls hold its confining stress by the same rule as the laboratory
    tests (its command fixes the material; the Python API sets it): a linear law's bound on
    young, Hertz's overlaps for Hertz–Mindlin grains."""
    from pendular.procedures.preparation import PrepareConfig
    from pendular.procedures.swcc import SwccConfig, SwccTest

    def swcc(**sample):
        return SwccTest(SwccConfig(sample=PrepareConfig(young=1e9, **sample)))

    with pytest.raises(ValueError, match="--confining = 750 Pa is below its valid minimum"):
        swcc()
    swcc(**HM)
    with pytest.raises(ValueError, match=r"--young = 1e\+09 Pa is outside the valid range \(0, "
                                         r".*\] Pa of Hertz–Mindlin grains .* at confining = "
                                         r"10 Pa"):
        swcc(confining=10.0, **HM)
