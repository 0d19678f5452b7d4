"""The job panel: statistics of the current job (whatever keys its ``stats`` has, with units)
and its warnings (click one to zoom to its place)."""

from __future__ import annotations

import math
from typing import Any

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QLabel,
    QListView,
    QListWidget,
    QListWidgetItem,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from galvo_core.drawing import Warning

#: Known stats keys: label, in display order. Unknown keys follow, labelled from their name.
STAT_LABELS: dict[str, str] = {
    "input_points": "Input points",
    "control_points": "Control points",
    "lines": "Lines",
    "cubics": "Cubics",
    "mark_points": "Mark points",
    "strokes": "Strokes",
    "laser_switches": "Laser switches",
    "corners": "Corners",
    "mark_length_mm": "Mark length",
    "jump_length_mm": "Jump length",
    "estimated_time_s": "Estimated time",
    "max_fit_error_um": "Largest fit error",
    "max_fit_error": "Largest fit error (units)",
    "quantum_units": "Coordinate grid (units)",
    "fit_bound_units": "Fit bound in effect (units)",
    "max_deviation_um": "Deviation (overlay)",
    "max_chord_height_um": "Largest chord height",
    "max_chord_height_bits": "Largest chord height (bits)",
    "dwell_points": "Dwell points",
}
#: Quantity/value column pairs side by side in the table.
STAT_COLUMNS = 3
#: Shown in bold: what an operator checks first.
KEY_STATS = ("control_points", "mark_points", "laser_switches", "estimated_time_s",
             "max_fit_error_um")


def _int(n: int) -> str:
    return f"{n:,}".replace(",", "\u2009")


def format_stat(key: str, value: Any) -> str:
    """A stats value with its unit, from the key's suffix."""
    if value is None:
        return "—"  # not measured (e.g. raw marks have no chord height)
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return _int(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "—"
        if key.endswith("_s"):
            if value >= 60:
                m, s = divmod(value, 60)
                return f"{int(m)} min {s:04.1f} s"
            return f"{value:.3f} s" if value < 10 else f"{value:.2f} s"
        if key.endswith("_mm"):
            return f"{value:,.2f} mm".replace(",", "\u2009")
        if key.endswith("_um"):
            if abs(value) < 5e-4:  # rounding noise of an exact fit (8.9e-14 µm): zero
                return "0 µm"
            return f"{value:.3g} µm" if value < 1000 else f"{value / 1000:.3f} mm"
        if key.endswith("_bits"):
            if abs(value) < 5e-7:
                return "0 bits"
            return f"{value:.3g} bits"
        if key.endswith("_deg"):
            return f"{value:.1f}°"
        if value.is_integer() and abs(value) < 1e15:
            return _int(int(value))
        if abs(value) < 1e-9:
            return "0 u" if "error" in key else "0"
        return f"{value:.4g} u" if "error" in key else f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(format_stat(key, v) for v in value)
    if isinstance(value, dict):
        return f"{len(value)} entries"
    return str(value)


def stat_label(key: str) -> str:
    if key in STAT_LABELS:
        return STAT_LABELS[key]
    words = key
    for suffix in ("_mm", "_um", "_s", "_bits", "_deg"):
        if words.endswith(suffix):
            words = words[: -len(suffix)]
    return words.replace("_", " ").capitalize()


def ordered_stats(stats: dict[str, Any]) -> list[tuple[str, Any]]:
    known = [(k, stats[k]) for k in STAT_LABELS if k in stats]
    # the time per layer shows in the layer table (app.layers_dock), not as "n entries"
    rest = sorted((k, v) for k, v in stats.items()
                  if k not in STAT_LABELS and k not in ("warnings", "layers"))
    return known + rest


class StatsPanel(QWidget):
    """A two-column table of the job's stats, and the selected path's counts."""

    #: width (pixels) one quantity/value pair needs; fewer pairs side by side when narrower
    PAIR_WIDTH = 220

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.columns = STAT_COLUMNS
        self.table = QTableWidget(0, 2 * STAT_COLUMNS)
        self.table.setObjectName("stats_table")
        self.table.verticalHeader().setVisible(False)
        self._set_columns(STAT_COLUMNS)
        self.table.horizontalHeader().setVisible(False)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.NoSelection)
        self.table.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.table.setShowGrid(False)
        self.table.setAlternatingRowColors(True)
        self.table.verticalHeader().setDefaultSectionSize(19)
        self.selection = QLabel("Click a path to see its counts.")
        self.selection.setObjectName("selection_label")
        self.selection.setWordWrap(True)
        self.selection.setStyleSheet("color: #3d4853; padding: 2px;")
        self.selection.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 2, 4, 2)
        lay.setSpacing(3)
        lay.addWidget(self.table, 1)
        lay.addWidget(self.selection)
        #: the text shown per key (tests read the window's numbers from here)
        self.shown: dict[str, str] = {}
        self.values: dict[str, Any] = {}

    def _set_columns(self, n: int) -> None:
        self.columns = n
        self.table.setColumnCount(2 * n)
        for c in range(n):
            self.table.horizontalHeader().setSectionResizeMode(
                2 * c, QHeaderView.ResizeMode.Stretch)
            self.table.horizontalHeader().setSectionResizeMode(
                2 * c + 1, QHeaderView.ResizeMode.ResizeToContents)

    def resizeEvent(self, ev) -> None:  # noqa: N802 - Qt API
        super().resizeEvent(ev)
        n = max(1, min(STAT_COLUMNS, self.width() // self.PAIR_WIDTH))
        if n != self.columns:
            self._set_columns(n)
            self.set_stats(self._last_stats, self._last_extra)

    _last_stats: dict[str, Any] | None = None
    _last_extra: dict[str, Any] | None = None

    def set_stats(self, stats: dict[str, Any] | None, extra: dict[str, Any] | None = None
                  ) -> None:
        self._last_stats, self._last_extra = stats, extra
        rows = ordered_stats(dict(stats or {}))
        rows += list((extra or {}).items())
        per_col = (len(rows) + self.columns - 1) // self.columns
        layout = (tuple(k for k, _ in rows), per_col, self.columns)
        if layout == getattr(self, "_layout", None):
            # the same rows in the same places (a re-run): only the texts that changed are
            # set (rebuilding the 50-odd items took 6 ms of the GUI thread per result)
            for r, (key, value) in enumerate(rows):
                before = self.values.get(key)
                self.values[key] = value
                text = format_stat(key, value)
                old_value = self.shown.get(key)
                self.shown[key] = text
                b = self.table.item(r % per_col, 2 * (r // per_col) + 1)
                if b is None:
                    continue
                if text != old_value:
                    b.setText(text)
                if key == "dwell_points" and bool(value) != bool(before):
                    if value:
                        b.setForeground(QBrush(QColor("#b35c00")))
                    else:
                        b.setData(Qt.ItemDataRole.ForegroundRole, None)
            return
        self._layout = layout
        self.table.clearContents()
        self.table.setRowCount(per_col)
        self.shown = {}
        self.values = {}
        bold = QFont()
        bold.setBold(True)
        for r, (key, value) in enumerate(rows):
            text = format_stat(key, value)
            self.shown[key] = text
            self.values[key] = value
            a = QTableWidgetItem(stat_label(key))
            a.setToolTip(key)
            b = QTableWidgetItem(text)
            b.setTextAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            if key in KEY_STATS:
                a.setFont(bold)
                b.setFont(bold)
            if key == "dwell_points" and value:
                b.setForeground(QBrush(QColor("#b35c00")))
            row, col = r % per_col, 2 * (r // per_col)
            self.table.setItem(row, col, a)
            self.table.setItem(row, col + 1, b)

    def shown_number(self, key: str) -> float:
        """The number the panel shows for ``key`` (parsed back from the text)."""
        text = self.shown[key].replace("\u2009", "").replace(",", "")
        return float(text.split()[0])

    def set_selection(self, text: str) -> None:
        self.selection.setText(text)


class WarningsPanel(QWidget):
    """The job's warnings (and a processing error, first, in red). Clicking one emits its
    index in :attr:`warnings` (-1 for the error line)."""

    activated = Signal(int)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.list = QListWidget()
        self.list.setObjectName("warnings_list")
        self.list.setWordWrap(True)
        self.list.setAlternatingRowColors(True)
        # word-wrapped rows are measured one by one: laid out all at once, 2,200 warnings
        # held the GUI thread 55 ms (quiet machine) to 290 ms (loaded); in batches, each
        # event-loop pass lays out 100 rows (at most 16 ms)
        self.list.setLayoutMode(QListView.LayoutMode.Batched)
        self.list.setBatchSize(100)
        self.list.itemClicked.connect(self._clicked)
        self.list.itemActivated.connect(self._clicked)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 2, 4, 2)
        lay.addWidget(self.list)
        self.warnings: tuple[Warning, ...] = ()
        self.error: str | None = None

    #: turns a core message into the window's words (e.g. CLI flags into control names)
    translate: staticmethod = staticmethod(lambda text: text)

    #: warnings listed at once; the rest follow this many per event-loop pass (a kerf that
    #: swallows 2,000 rings warns 2,000 times: 30 ms of the GUI thread in one go)
    WARNINGS_PER_PASS = 200

    def set_warnings(self, warnings: tuple[Warning, ...] | list[Warning],
                     error: str | None = None) -> None:
        warnings = tuple(warnings)
        tr = self.translate
        error = tr(error) if error else error
        if warnings == self.warnings and error == self.error and self.list.count():
            return  # the same list (a re-run that warns alike)
        self.warnings = warnings
        self.error = error
        self.list.clear()
        self._pending = iter(enumerate(self.warnings))
        if error:
            item = QListWidgetItem(f"✖ {error}")
            item.setForeground(QBrush(QColor("#b00020")))
            item.setData(Qt.ItemDataRole.UserRole, -1)
            item.setToolTip(error)
            self.list.addItem(item)
        if not error and not self.warnings:
            item = QListWidgetItem("✓ no warnings")
            item.setForeground(QBrush(QColor("#2e7d32")))
            item.setData(Qt.ItemDataRole.UserRole, None)
            self.list.addItem(item)
        self._add_more()

    def _add_more(self) -> None:
        """The next WARNINGS_PER_PASS warnings of the list; the rest in a later pass."""
        pending = getattr(self, "_pending", None)
        if pending is None:
            return
        tr = self.translate
        brush = QBrush(QColor("#8a4b00"))
        n = 0
        for i, w in pending:
            where = f"line {w.line}, col {w.col}: " if w.line else ""
            item = QListWidgetItem(f"⚠ {where}{tr(w.message)}")
            item.setForeground(brush)
            item.setData(Qt.ItemDataRole.UserRole, i)
            item.setToolTip(tr(str(w)))
            self.list.addItem(item)
            n += 1
            if n == self.WARNINGS_PER_PASS:
                QTimer.singleShot(0, lambda it=pending: self._add_more()
                                  if self._pending is it else None)
                return
        self._pending = None

    def flush(self) -> None:
        """List every warning now (the ones still waiting for a pass)."""
        while getattr(self, "_pending", None) is not None:
            self._add_more()

    def texts(self) -> list[str]:
        self.flush()
        return [self.list.item(i).text() for i in range(self.list.count())]

    def _clicked(self, item: QListWidgetItem) -> None:
        idx = item.data(Qt.ItemDataRole.UserRole)
        if idx is not None:
            self.activated.emit(int(idx))
