"""The README's special-shape screenshot: the window on a sample with the Plan tab raised.

Usage (under a display or Xvfb)::

    python docs/examples/screenshot_plan.py resources/flacon.glassbench docs/img/window_flacon.png [SECONDS]

Unlike ``glassbench --screenshot`` (which waits for "converged"), this grabs the window once the
preview is converged or after ``SECONDS`` (default 240) of refining, whichever comes first, so
the status bar may say "Denoised preview · N samples": the picture shows what it is.
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from PySide6.QtCore import QSettings, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from app import layout  # noqa: E402
from app.startup import grab_window  # noqa: E402
from app.window import MainWindow  # noqa: E402
from engine.files.project import load_project  # noqa: E402


def main(project: str, out: str, seconds: float = 240.0) -> int:
    app = QApplication.instance() or QApplication([])
    settings = QSettings(str(Path(tempfile.mkdtemp()) / "settings.ini"), QSettings.IniFormat)
    design, assets = load_project(project)
    window = MainWindow(design, assets, project, settings=settings)
    window.resize(layout.DEFAULT_SIZE)
    window.show()
    window.docks["plan"].raise_()
    rc = window.render_controller

    def done() -> bool:
        return rc.ended_generation == rc.generation and not window.resize_timer.isActive()

    def grab():
        grab_window(window).save(out)
        print(f"wrote {out} ({window.statusBar().currentMessage() or 'status bar above'})")
        window.undo_stack.setClean()
        window.close()
        app.quit()

    poll = QTimer(window)
    poll.timeout.connect(lambda: done() and (poll.stop(), grab()))
    poll.start(200)
    QTimer.singleShot(int(seconds * 1000), lambda: poll.isActive() and (poll.stop(), grab()))
    app.exec()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else 240.0))
