"""The layer table: one row per pen the job uses, with its laser settings and passes.

Every edit emits ``changed(PenTable)`` with the whole new table (a frozen, hashable value:
the caller re-runs what depends on it, e.g. ``galvo_core.layers.apply_pens`` for the time
per layer and the export). The editors cannot hold a value the core would refuse (spin
boxes bounded: speeds > 0, power 0..100 %, passes 1..1000), so no edit can fail.

API for the window (the coordinator wires it beside the processing panel)::

    panel = LayersPanel(table)            # a PenTable (default: the default laser)
    panel.set_pens(pens)                  # the pens of the current job: one row each
    panel.set_layer_times(job.stats.get("layers", []))   # the time column
    panel.changed.connect(on_pens)        # on_pens(table: PenTable)
    panel.table()                         # the current PenTable
    panel.set_table(table)                # e.g. loaded from a TOML file (no signal)
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QCheckBox,
    QDoubleSpinBox,
    QHeaderView,
    QLabel,
    QSpinBox,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from galvo_core.layers import MAX_PASSES, LayerSettings, PenTable

#: (key, header, lo, hi, decimals); key is a LayerSettings / LaserParams field
COLUMNS: tuple[tuple[str, str, float, float, int], ...] = (
    ("passes", "Passes", 1, MAX_PASSES, 0),
    ("mark_speed_mm_s", "Mark mm/s", 0.1, 20000, 1),
    ("jump_speed_mm_s", "Jump mm/s", 1, 50000, 0),
    ("power_percent", "Power %", 0, 100, 1),
    ("frequency_khz", "Freq kHz", 1, 4000, 1),
    ("pulse_width_ns", "Pulse ns", 0, 65535, 0),  # 0: not set
    ("laser_on_delay_us", "On µs", 0, 65535, 0),
    ("laser_off_delay_us", "Off µs", 0, 65535, 0),
    ("polygon_delay_us", "Poly µs", 0, 65535, 0),
)
FIXED = ("Pen", "On")
TIME_HEADER = "Time s"


class LayersPanel(QWidget):
    """A table of pen layers; edits emit :attr:`changed` with the new :class:`PenTable`."""

    changed = Signal(object)  # PenTable

    def __init__(self, table: PenTable | None = None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._table = table or PenTable()
        self._pens: list[int] = [p.pen for p in self._table.pens] or [1]
        self._times: dict[int, float] = {}
        self._building = False
        self.grid = QTableWidget(0, len(FIXED) + len(COLUMNS) + 1)
        self.grid.setObjectName("layers_table")
        self.grid.setHorizontalHeaderLabels(
            list(FIXED) + [c[1] for c in COLUMNS] + [TIME_HEADER])
        self.grid.verticalHeader().setVisible(False)
        self.grid.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.
                                                          ResizeToContents)
        self.total = QLabel("")
        self.total.setObjectName("layers_total")
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.grid)
        lay.addWidget(self.total)
        self._rebuild()

    # ------------------------------------------------------------------ API
    def table(self) -> PenTable:
        return self._table

    def set_table(self, table: PenTable) -> None:
        """Show ``table`` (no signal). Its pens join the rows."""
        self._table = table
        self._pens = sorted(set(self._pens) | {p.pen for p in table.pens})
        self._rebuild()

    def set_pens(self, pens: Iterable[int]) -> None:
        """One row per pen in ``pens`` (the job's), in pen order (the marking order)."""
        new = sorted({int(p) for p in pens}) or [1]
        if new != self._pens:
            self._pens = new
            self._rebuild()

    def set_layer_times(self, rows: Iterable[Mapping[str, Any]]) -> None:
        """The time column from ``job.stats["layers"]`` (pen, estimated_time_s)."""
        self._times = {int(r["pen"]): float(r["estimated_time_s"]) for r in rows}
        col = self.grid.columnCount() - 1
        for i, pen in enumerate(self._pens):
            item = self.grid.item(i, col)
            if item is not None:
                t = self._times.get(pen)
                item.setText("" if t is None else f"{t:.3f}")
        total = sum(self._times.values())
        self.total.setText(f"total {total:.3f} s" if self._times else "")

    def editor(self, pen: int, key: str) -> QWidget:
        """The editor widget of one cell (for tests and keyboard focus)."""
        row = self._pens.index(pen)
        col = len(FIXED) + [c[0] for c in COLUMNS].index(key) if key != "enabled" else 1
        w = self.grid.cellWidget(row, col)
        assert w is not None
        return w

    # ------------------------------------------------------------------ internals
    def _rebuild(self) -> None:
        self._building = True
        try:
            g = self.grid
            g.setRowCount(len(self._pens))
            for i, pen in enumerate(self._pens):
                s = self._table.settings(pen)
                item = QTableWidgetItem(f"{pen}")
                item.setFlags(Qt.ItemFlag.ItemIsEnabled)
                item.setBackground(QColor(s.display_colour))
                item.setForeground(QColor("white"))
                g.setItem(i, 0, item)
                on = QCheckBox()
                on.setObjectName(f"layer_{pen}_enabled")
                on.setChecked(s.enabled)
                on.toggled.connect(lambda v, pen=pen: self._edit(pen, "enabled", bool(v)))
                g.setCellWidget(i, 1, on)
                for k, (key, _h, lo, hi, dec) in enumerate(COLUMNS):
                    g.setCellWidget(i, len(FIXED) + k, self._spin(pen, s, key, lo, hi, dec))
                t = self._times.get(pen)
                ti = QTableWidgetItem("" if t is None else f"{t:.3f}")
                ti.setFlags(Qt.ItemFlag.ItemIsEnabled)
                g.setItem(i, g.columnCount() - 1, ti)
        finally:
            self._building = False

    def _spin(self, pen: int, s: LayerSettings, key: str, lo: float, hi: float,
              dec: int) -> QAbstractSpinBox:
        if key == "passes":
            value: float = s.passes
        elif key == "pulse_width_ns":
            value = s.pulse_width_ns or 0
        else:
            value = getattr(s.laser, key)
        sp: QAbstractSpinBox
        if dec == 0:
            box = QSpinBox()
            box.setRange(int(lo), int(hi))
            if key == "pulse_width_ns":
                box.setSpecialValueText("off")  # 0: the board keeps its own
            box.setValue(int(round(value)))
            box.valueChanged.connect(lambda v, pen=pen, key=key: self._edit(pen, key, int(v)))
            sp = box
        else:
            dbox = QDoubleSpinBox()
            dbox.setDecimals(dec)
            dbox.setRange(lo, hi)
            dbox.setValue(float(value))
            dbox.valueChanged.connect(
                lambda v, pen=pen, key=key: self._edit(pen, key, float(v)))
            sp = dbox
        sp.setKeyboardTracking(False)  # typed values commit on Enter / focus out
        sp.setObjectName(f"layer_{pen}_{key}")
        return sp

    def _edit(self, pen: int, key: str, value: Any) -> None:
        if self._building:
            return
        s = self._table.settings(pen)
        if key == "pulse_width_ns":
            value = int(value) or None
        elif key not in ("passes", "enabled"):
            value = float(value)
        new = s.replace(**{key: value})
        if new == s:
            return
        self._table = self._table.with_pen(new)
        if key == "enabled":
            self.grid.item(self._pens.index(pen), self.grid.columnCount() - 1).setText("")
        self.changed.emit(self._table)
