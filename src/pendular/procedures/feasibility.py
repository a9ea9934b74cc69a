"""What a laboratory test can run, checked before anything is made: a quasi-static loading
(its inertial number), a run that ends in reasonable time (its steps and particle-steps), and
stiffnesses at which the radius growth settles and the servoed walls hold the stress (the
linear law's bounds, and Hertz's law's overlaps for Hertz–Mindlin grains)."""

from __future__ import annotations

from pendular.procedures.config import inertial_number
from pendular.procedures.preparation import (MAX_STRESS, PEAK_FORCE_OVER_STRESS, hertz_overlap,
    hertz_stress_over_young, pwave_step)
from pendular.utils.parameters import fail, spec_of


#: Largest inertial number of a quasi-static shear (GDR MiDi 2004: I < 1e-3 quasi-static,
#: dense flow beyond; at 1e-2 the wall and Love–Weber stresses already differ by a few %).
MAX_INERTIAL_NUMBER = 1e-2


#: Most shear steps a run may ask for without --force (about 1 h at 1,000 spheres here).
MAX_SHEAR_STEPS = 20_000_000


#: Most particle-steps (spheres x steps) of a loading without --force: about 7 h at
#: ESTIMATE_RATE, a night's run; MAX_SHEAR_STEPS bounds the steps of smaller samples.
MAX_PARTICLE_STEPS = 1e11


#: Smallest prep_stress / young of a preparation: the radius growth (1e-4 R per step) settles
#: only when the overlaps at the target stress (about 8 prep_stress / young R) are well above
#: its step (60 spheres: 1.7e-4 settles in 7,400 steps, 5e-5 not in 2,000,000).
MIN_PREP_STRESS_OVER_YOUNG = 1e-4


#: Smallest confining / young: below, the six servoed walls do not hold the confining stress
#: within the 1 % tolerance (60 spheres, young 1e6 Pa: 5 Pa is static after 8,600 steps,
#: 3 Pa not after 250,000; the walls hover at 10-30 Pa).
MIN_CONFINING_OVER_YOUNG = 5e-6


#: Particle-steps per second assumed for run-time estimates (one core of the 2-core machine).
ESTIMATE_RATE = 4e6


def quasi_static_number(rate, sample, pressure):
    """The inertial number [-] of the strain rate ``rate`` [1/s] for the grains of ``sample``
    (a PrepareConfig) at the stress ``pressure`` [Pa]."""
    return inertial_number(rate, sample.radius, sample.density, pressure)


def check_feasible(config, force=False):
    """Refuse, before anything runs, a test that cannot be quasi-static (inertial number above
    MAX_INERTIAL_NUMBER at the lowest stress of its path) or would not finish in reasonable
    time (more than MAX_SHEAR_STEPS steps of a path whose length is known), with the estimate,
    or whose equilibrium phases cannot settle (a stress of the path below
    MIN_CONFINING_OVER_YOUNG young; a preparation with prep_stress below
    MIN_PREP_STRESS_OVER_YOUNG young; with Hertz–Mindlin contacts the overlaps these set,
    check_hertz_equilibria); ``force`` lets an expert run it anyway. A path
    table's stages that name their own rates are held to the same bounds, each named by its
    file and stage. Output periods must fit the loading. ValueError naming the setting."""
    sample = config.sample
    rate = config.rate()
    # the option setting the rate: --strain-rate, or a simple shear's --shear-rate
    flag = spec_of(config.rate_settings(), "strain_rate").flag
    rate_name = f"{flag[2:].replace('-', ' ')} {rate:.3g} 1/s"
    pressure = config.reference_pressure()
    number = quasi_static_number(rate, sample, pressure)
    dt = pwave_step(sample.radius, sample)    # the stiffness rule's step is larger
    steps = config.estimated_steps()
    where = (f"confining = {pressure:g} Pa" if pressure == sample.confining
             else f"{pressure:g} Pa, the lowest stress of the path")
    # the most steps of a loading: MAX_SHEAR_STEPS, fewer for a large sample
    most = min(MAX_SHEAR_STEPS, MAX_PARTICLE_STEPS / sample.particles)
    large = ("--particles",) if most < MAX_SHEAR_STEPS else ()

    def too_long(what, steps, rate_name, remedy):
        hours = sample.particles * steps / ESTIMATE_RATE / 3600.0
        return ValueError(
            f"{what} would take {steps:.3g} steps (dt = {dt:.3g} s, {rate_name}; about "
            f"{hours:.3g} h here at {sample.particles} spheres), outside the valid range "
            f"[1, {most:.3g}]: {remedy} (or --force)")

    if not force and number > MAX_INERTIAL_NUMBER:
        raise ValueError(
            f"{rate_name} gives the inertial number I = {number:.3g}, outside the quasi-static "
            f"range (0, {MAX_INERTIAL_NUMBER:g}] at {where}: lower {flag} / --inertial-number "
            "(or --force)")
    if not force and steps is not None and steps > most:
        raise too_long(config.LOADING,
                       steps, rate_name, f"raise {flag} / --inertial-number, or lower "
                       f"{', '.join(('--young', *large, *config.LENGTH))}")
    for stage, stage_rate, stage_steps in config.stage_rates() if not force else ():
        stage_number = quasi_static_number(stage_rate, sample, pressure)
        if stage_number > MAX_INERTIAL_NUMBER:
            raise ValueError(
                f"{stage}: strain rate {stage_rate:.3g} 1/s gives the inertial number I = "
                f"{stage_number:.3g}, outside the quasi-static range (0, "
                f"{MAX_INERTIAL_NUMBER:g}] at {where}: lower it (or --force)")
        if stage_steps is not None and stage_steps > most:
            raise too_long(stage, stage_steps, f"strain rate {stage_rate:.3g} 1/s",
                           "raise its strain rate")
    if sample.contact == "hertz-mindlin":
        if not force:
            check_hertz_equilibria(config, pressure)
    else:
        if (not force and config.sample_path is None
                and sample.prep_stress < MIN_PREP_STRESS_OVER_YOUNG * sample.young):
            raise ValueError(
                f"young = {sample.young:g} Pa is outside the valid range (0, "
                f"{sample.prep_stress / MIN_PREP_STRESS_OVER_YOUNG:g}] Pa for the preparation at "
                f"prep_stress = {sample.prep_stress:g} Pa: the radius growth cannot settle at "
                f"overlaps below {MIN_PREP_STRESS_OVER_YOUNG:g} of the radius (it would run "
                "2,000,000 steps and stop); lower young (or --force)")
        if not force and pressure < MIN_CONFINING_OVER_YOUNG * sample.young:
            name = "confining" if pressure == sample.confining else "the path's lowest stress"
            raise ValueError(
                f"{name} = {pressure:g} Pa is outside the valid range "
                f"[{MIN_CONFINING_OVER_YOUNG * sample.young:g}, {MAX_STRESS:g}] Pa for young = "
                f"{sample.young:g} Pa: below {MIN_CONFINING_OVER_YOUNG:g} young the servoed walls "
                "never hold the confining stress (the equilibrium would run to its step limit); "
                "raise confining or lower young (or --force)")
    for name in ("vtk_every", "checkpoint_every"):
        value = getattr(config, name)
        if steps is not None and value is not None and value > max(steps, 1.0) + 1:
            raise fail(config, name, f"{name} = {value} is outside the valid range "
                       f"[0, {int(steps) + 1}]: the shear has about {int(steps)} steps")


def check_hertz_equilibria(config, pressure):
    """check_feasible's bounds on the equilibria of a test with Hertz–Mindlin contacts, the
    linear law's MIN_PREP_STRESS_OVER_YOUNG and MIN_CONFINING_OVER_YOUNG turned into the
    overlaps they set (PEAK_FORCE_OVER_STRESS times them, of the radius, at the most loaded
    contact) and back into stresses by Hertz's law (preparation.hertz_overlap): at a stress
    p a Hertz contact overlaps by about (15 p / E)^(2/3) R, far more than a linear spring's
    8 p / E R, so it admits a far stiffer E. ``pressure``: the lowest stress of the path [Pa].
    ValueError naming --young and its valid range. A configuration without ``sample_path``
    (an SWCC) prepares its own sample."""
    sample = config.sample
    young, poisson = sample.young, sample.poisson
    sample_path = getattr(config, "sample_path", None)

    def stiffest(stress, overlap):
        return stress / hertz_stress_over_young(overlap, poisson)

    grown = PEAK_FORCE_OVER_STRESS * MIN_PREP_STRESS_OVER_YOUNG
    if sample_path is None and young > stiffest(sample.prep_stress, grown):
        raise ValueError(
            f"--young = {young:g} Pa is outside the valid range (0, "
            f"{stiffest(sample.prep_stress, grown):g}] Pa of Hertz–Mindlin grains (poisson = "
            f"{poisson:g}) for the preparation at prep_stress = {sample.prep_stress:g} Pa: the "
            f"most loaded contact would overlap by "
            f"{hertz_overlap(sample.prep_stress, young, poisson):.3g} of the radius, below the "
            f"{grown:g} the radius growth needs to settle (it would run 2,000,000 steps and "
            "stop); lower --young, or prepare at a larger prep_stress and pass --sample (or "
            "--force)")
    held = PEAK_FORCE_OVER_STRESS * MIN_CONFINING_OVER_YOUNG
    if young > stiffest(pressure, held):
        name = "confining" if pressure == sample.confining else "the path's lowest stress"
        raise ValueError(
            f"--young = {young:g} Pa is outside the valid range (0, "
            f"{stiffest(pressure, held):g}] Pa of Hertz–Mindlin grains (poisson = {poisson:g}) "
            f"at {name} = {pressure:g} Pa: the most loaded contact would overlap by "
            f"{hertz_overlap(pressure, young, poisson):.3g} of the radius, below the {held:g} "
            "at which the servoed walls hold the stress (the equilibrium would run to its step "
            f"limit); lower --young or raise {name} (or --force)")
