"""The figures of a run, drawn from synthetic histories: the q-p' stress path (Eq. 3.43) beside
q-p, titles on every figure, legends and labels in words with symbols, tick labels on both
panels of triaxial.png."""

import os

import numpy as np
import pytest

from conftest import assert_drawn
from pendular.io import plots
from pendular.procedures import tension_report
from pendular.procedures.reference import KIM_2001
from pendular.procedures.tension import TensionConfig, tension_sample

#: Code names that must not reach a legend or a label.
CODE_NAMES = ("psi_interface", "sigma_capillary", "sigma_effective", "packing_state", "psi ",
              "e0.72_w")
ROWS = 80


def diagonal(values):
    """(rows, 3, 3) tensors with the (rows, 3) ``values`` on their diagonals."""
    return np.einsum("ri,ij->rij", values, np.eye(3))


def triaxial_history(wet=True):
    """A triaxial history of ROWS records to 5 % strain: the lateral walls at 750 Pa, the axial
    stress 750 Pa + q with the peak of q (4 kPa) at 3 %; wet, a capillary stress ψ of a few kPa,
    larger axially, the interface term a tenth of it."""
    strain = np.linspace(0.0, 0.05, ROWS)
    q = 4000.0 * strain / 0.03 * np.exp(1.0 - strain / 0.03)
    sigma = np.column_stack([np.full(ROWS, 750.0), np.full(ROWS, 760.0), 750.0 + q])
    history = {"step": np.arange(ROWS) * 100, "axial_strain": strain,
               "volumetric_strain": 0.002 - 0.2 * strain, "sigma_wall": sigma}
    if wet:
        psi = diagonal(np.column_stack([3000.0 - 1e4 * strain, 3000.0 - 1e4 * strain,
                                        3200.0 - 1.2e4 * strain]))
        history.update({"saturation": 0.02 - 0.05 * strain, "psi": psi,
                        "psi_interface": 0.1 * psi, "sigma_capillary": -psi,
                        "sigma_effective": diagonal(sigma) + psi,
                        "sigma_effective_complete": diagonal(sigma) + 1.1 * psi})
    return history


def invariants(diagonals):
    """(p, q) [kPa] of (rows, 3) principal stresses [Pa], z axial: p = mean, q = z - mean(x, y)."""
    return diagonals.mean(axis=1) / 1e3, (diagonals[:, 2] - diagonals[:, :2].mean(axis=1)) / 1e3


def legend_texts(figure):
    return [text.get_text() for axes in figure.axes if axes.get_legend() is not None
            for text in axes.get_legend().get_texts()]


def titles(figure):
    """Every title of the figure: its axes' and its suptitle."""
    found = [axes.get_title() for axes in figure.axes]
    if figure._suptitle is not None:
        found.append(figure._suptitle.get_text())
    return [text for text in found if text.strip()]


@pytest.fixture
def saved(monkeypatch):
    """File name -> what the figure saved there shows (its y labels and their font sizes, legend
    texts, titles), for every figure passed to save_figure, each still saved."""
    figures = {}
    original = plots.save_figure

    def keep(figure, path, dpi=120):
        figures[os.path.basename(path)] = {
            "ylabels": [axes.get_ylabel() for axes in figure.axes],
            "sizes": [axes.yaxis.label.get_fontsize() for axes in figure.axes],
            "legends": legend_texts(figure), "titles": titles(figure)}
        return original(figure, path, dpi=40)

    monkeypatch.setattr(plots, "save_figure", keep)
    return figures


def test_the_stress_path_of_a_wet_run_draws_q_p_effective_beside_q_p():
    history = triaxial_history()
    figure = plots.stress_path_figure(history, "N = 200", direction="compression")
    axes = figure.axes[0]
    assert axes.get_xlabel() == "mean stress p, p′ [kPa]"
    assert axes.get_ylabel() == "deviator stress q, q′ [kPa]"
    lines = {line.get_label(): line for line in axes.get_lines()}
    expected = {"net stress: q–p": invariants(history["sigma_wall"]),
                "effective stress (Eq. 3.43): q′–p′":
                    invariants(np.diagonal(history["sigma_effective"], axis1=1, axis2=2)),
                "complete effective stress (ψ + interface term): q′–p′":
                    invariants(np.diagonal(history["sigma_effective_complete"], axis1=1,
                                           axis2=2))}
    for label, (p, q) in expected.items():
        assert np.allclose(lines[label].get_xdata(), p) and np.allclose(lines[label].get_ydata(), q)
    # the effective path lies to the right of the net one by the mean of ψ, the same q shape
    p_net, _ = expected["net stress: q–p"]
    p_effective, _ = expected["effective stress (Eq. 3.43): q′–p′"]
    assert np.allclose(p_effective - p_net,
                       np.trace(history["psi"], axis1=1, axis2=2) / 3.0 / 1e3)
    # the peak of q marked on each path, at the record of the net peak
    peak = int(np.argmax(invariants(history["sigma_wall"])[1]))
    markers = [line for line in axes.get_lines() if line.get_marker() == "o"]
    assert len(markers) == 3
    assert all(line.get_xdata()[0] == pytest.approx(expected[label][0][peak])
               for line, label in zip(markers, expected))
    assert "Stress paths" in axes.get_title() and "N = 200" in axes.get_title()
    plots.pyplot().close(figure)


def test_the_stress_path_of_a_dry_run_is_q_against_p():
    figure = plots.stress_path_figure(triaxial_history(wet=False), "N = 200")
    axes = figure.axes[0]
    assert (axes.get_xlabel(), axes.get_ylabel()) == ("mean stress p [kPa]",
                                                      "deviator stress q [kPa]")
    assert legend_texts(figure) == ["net stress: q–p"]
    plots.pyplot().close(figure)


def test_both_panels_of_the_triaxial_figure_have_tick_labels():
    figure = plots.history_figure(triaxial_history(), "N = 200")
    figure.canvas.draw()
    top, bottom = figure.axes
    for axes in (top, bottom):
        shown = [label.get_text() for label in axes.get_xticklabels() if label.get_visible()]
        assert any(shown), axes.get_ylabel()
    assert "Drained triaxial compression" in top.get_title()
    plots.pyplot().close(figure)


def test_a_triaxial_run_writes_every_plot_titled_in_words(saved, tmp_path):
    """triaxial.png, plots/ (q/p, εv, Sr, capillary stresses) and plots/stress_path.png: each
    written, titled, its legends and y labels in words and symbols (no code name), the y
    labels short and not shrunk."""
    history = triaxial_history()
    title = plots.run_label({"particles": 200, "confining": 750.0, "suction": 30000.0,
                             "contact_angle": 20.0}, 0.41)
    assert "contact angle θ = 20°" in title
    plots.plot_history(history, tmp_path / "triaxial.png", title)
    plots.write_plots(history, tmp_path / "plots", title)
    plots.plot_stress_path(history, tmp_path / "plots" / "stress_path.png", title, "compression")
    names = sorted(p.name for p in (tmp_path / "plots").iterdir())
    assert names == ["capillary_stress.png", "q_p.png", "saturation.png", "stress_path.png",
                     "volumetric_strain.png"]
    for path in (tmp_path / "plots").iterdir():
        assert_drawn(path)
    assert sorted(saved) == sorted(["triaxial.png", *names])
    for name, shown in saved.items():
        assert any(title in text for text in shown["titles"]), name
        for text in shown["ylabels"] + shown["legends"]:
            assert not any(code in text for code in CODE_NAMES), (name, text)
        for label, size in zip(shown["ylabels"], shown["sizes"]):
            assert all(len(line) <= 30 for line in label.split("\n")) and size >= 9, name
    capillary = saved["capillary_stress.png"]
    assert capillary["ylabels"] == ["ψ [kPa]", "interface term [kPa]",
                                    "σ$_\\mathrm{cap}$ [kPa]"]
    assert {"ψ, axial z", "interface term, lateral x"} <= set(capillary["legends"])
    assert "q′–p′" in " ".join(saved["stress_path.png"]["legends"])


def test_the_tension_plots_are_titled_and_name_the_cases_in_words(saved, tmp_path):
    config = TensionConfig(cases=((0.72, 0.01),), sample=tension_sample(particles=200))
    summary = {"case": "e0.72_w1.00", "void_ratio_target": 0.72, "water_content_target": 0.01,
               "water_content": 0.0101, "void_ratio": 0.721, "tensile_strength_pa": 600.0}
    extension = np.linspace(0.0, 0.05, 50)
    history = {"axial_strain": -extension,
               "tensile_stress": 600.0 * np.exp(-((extension - 0.01) / 0.01) ** 2)}
    plots.plot_curves([summary], {"e0.72_w1.00": history}, tmp_path, config)
    plots.plot_strength([summary], config, KIM_2001,
                        tension_report.strength_predictions([summary], config),
                        tmp_path / "strength_vs_water.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "strength_vs_water.png", "tension_all.png", "tension_e0.72_w1.00.png"]
    assert sorted(saved) == ["strength_vs_water.png", "tension_all.png",
                             "tension_e0.72_w1.00.png"]
    for name, shown in saved.items():
        assert any("contact angle θ = 0°" in text for text in shown["titles"]), name
        for text in shown["ylabels"] + shown["legends"]:
            assert not any(code in text for code in CODE_NAMES), (name, text)
    assert saved["tension_all.png"]["legends"] == ["e = 0.72, w = 1 %"]
    assert ("regular packing prediction (Ch. 4), isotropic BCC"
            in saved["strength_vs_water.png"]["legends"])


def test_a_constant_p_stress_path_is_drawn_upright_and_titled_with_p_and_b():
    """At constant p the path is vertical: its p axis spans at least half the q range around
    p, not the 0.7500-0.7512 kPa of the round-off; the title names the constant p, and a true
    triaxial test's b, which its q (von Mises) and the figure's label follow."""
    history = triaxial_history(wet=False)
    sigma = history["sigma_wall"]
    q = sigma[:, 2] - sigma[:, :2].mean(axis=1)
    sigma[:, :2] = (750.0 - q / 3.0)[:, None] + np.linspace(0.0, 1.2, ROWS)[:, None]
    sigma[:, 2] = 750.0 + 2.0 * q / 3.0
    figure = plots.stress_path_figure(history, "constant p", "compression")
    low, high = figure.axes[0].get_xlim()
    assert high - low >= 0.49 * np.ptp(q) / 1e3 and low < 0.75 < high
    plots.pyplot().close(figure)
    label = plots.run_label({"particles": 200, "confining": 750.0, "constant_p": True,
                             "b": 0.5}, 0.395)
    assert "constant p = 0.75 kPa" in label and "b = 0.5" in label and "σ3" not in label
    assert "n0 = 0.395" in label
    figure = plots.history_figure(history, label, "compression", b=0.5)
    assert figure.axes[0].get_ylabel() == "von Mises stress q [kPa]"
    plots.pyplot().close(figure)
