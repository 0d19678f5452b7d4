"""The layer table: edits emit the new PenTable; rows follow the job's pens; times shown."""

from __future__ import annotations

import pytest

pytest.importorskip("pytestqt")

from app.layers_panel import LayersPanel  # noqa: E402
from galvo_core.layers import LayerSettings, PenTable, apply_pens  # noqa: E402
from galvo_core.params import LaserParams  # noqa: E402

pytestmark = pytest.mark.gui


def test_edits_emit_the_new_table(qtbot):
    panel = LayersPanel(PenTable(LayerSettings(0, LaserParams(mark_speed_mm_s=300))))
    qtbot.addWidget(panel)
    panel.set_pens([2, 1, 2])
    assert panel.grid.rowCount() == 2
    assert [panel.grid.item(i, 0).text() for i in range(2)] == ["1", "2"]
    got = []
    panel.changed.connect(got.append)
    panel.editor(2, "power_percent").setValue(85.0)
    assert len(got) == 1 and isinstance(got[0], PenTable)
    assert got[0].settings(2).laser.power_percent == 85.0
    assert got[0].settings(1).laser.power_percent == 50.0  # untouched
    assert got[0].settings(2).laser.mark_speed_mm_s == 300  # from the profile
    panel.editor(1, "passes").setValue(3)
    panel.editor(1, "enabled").setChecked(False)
    panel.editor(2, "pulse_width_ns").setValue(120)
    last = got[-1]
    assert last.settings(1).passes == 3 and not last.settings(1).enabled
    assert last.settings(2).pulse_width_ns == 120
    assert panel.table() is last
    hash(last)  # a value the pipeline can cache by


def test_editors_cannot_hold_refused_values(qtbot):
    panel = LayersPanel()
    qtbot.addWidget(panel)
    panel.editor(1, "power_percent").setValue(250)
    panel.editor(1, "mark_speed_mm_s").setValue(-10)
    s = panel.table().settings(1)
    assert s.laser.power_percent == 100 and s.laser.mark_speed_mm_s > 0


def test_set_table_and_times(qtbot):
    import numpy as np

    from galvo_core.field import FieldMap
    from galvo_core.job import Job, Stroke

    t = PenTable(LayerSettings(0), (LayerSettings(1, LaserParams(power_percent=33), passes=2),
                                    LayerSettings(4)))
    panel = LayersPanel()
    qtbot.addWidget(panel)
    got = []
    panel.changed.connect(got.append)
    panel.set_table(t)
    assert not got
    assert panel.editor(1, "power_percent").value() == 33
    assert panel.editor(1, "passes").value() == 2
    fm = FieldMap(1.0, (0.0, 0.0), 65536, 110.0)
    job = Job("x", "", fm, {}, {}, (
        Stroke("contour", 0, False, np.array([[0, 0], [9000, 0]]), (), 1),
        Stroke("contour", 1, False, np.array([[0, 100], [9000, 100]]), (), 4)))
    job = apply_pens(job, t)
    panel.set_pens(s.pen for s in job.strokes)
    panel.set_layer_times(job.stats["layers"])
    col = panel.grid.columnCount() - 1
    times = [float(panel.grid.item(i, col).text()) for i in range(2)]
    assert times[0] > times[1] > 0  # pen 1 marks twice
    assert panel.total.text().startswith("total ")
