"""sphinx-gallery helper for the documentation build: an image scraper for ``curvefair.plot``.

:func:`curvefair.plot.figure` returns a ``matplotlib.figure.Figure`` that pyplot does not
manage (so that it never opens a window nor leaks into pyplot's figure list); sphinx-gallery's
own matplotlib scraper only sees pyplot's figures. This scraper saves every ``Figure`` bound to
a name in the example's namespace, or left as the value of a code block's last expression, that
it has not saved before, and then hands over to the matplotlib scraper for pyplot figures.
"""

from __future__ import annotations

from typing import Any

from sphinx_gallery.scrapers import figure_rst, matplotlib_scraper


def curvefair_scraper(block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any],
                      **kwargs: Any) -> str:
    from matplotlib.figure import Figure

    seen = block_vars.setdefault("curvefair_saved_figures", set())
    glb = block_vars.get("example_globals", {})
    candidates = [v for v in glb.values() if isinstance(v, Figure)]
    last = glb.get("___") if isinstance(glb.get("___"), Figure) else None
    if last is not None:
        candidates.append(last)
    paths = []
    images = block_vars["image_path_iterator"]
    for fig in candidates:
        if id(fig) in seen:
            continue
        seen.add(id(fig))
        path = images.next()
        fig.savefig(path, dpi=90)
        paths.append(path)
    rst = figure_rst(paths, gallery_conf["src_dir"]) if paths else ""
    return rst + matplotlib_scraper(block, block_vars, gallery_conf, **kwargs)
