"""Self-contained HTML reports a designer opens in the browser (offline: plotly.js, the
page's script and every number are embedded).

* :func:`write_study_page` — ``results/<study>/report.html``: the Pareto scatter matrix and
  parallel coordinates (click a point for its card), a card per exported design (parameters
  and metrics against the baseline, rounded build dimensions, constraint margins, a 3-D view
  of the workspace hull coloured by κ with the mechanism at its nominal pose, slices, files),
  the invalid and failed candidates with their reasons, the study definition and provenance.
* :func:`compare_html` — the same kind of page for ``pkmlab compare``: designs side by side
  and their workspace hulls overlaid.
"""

from .compare_page import compare_html
from .study_page import REPORT_NAME, write_study_page

__all__ = ["write_study_page", "compare_html", "REPORT_NAME"]
