"""``pmnav view``: a run's tree, what it knew, its map and its camera in a browser page.

The page (``static/view.html``: one file of HTML, CSS and JavaScript, nothing to build)
is served by the standard library's ``ThreadingHTTPServer`` (``server.py``) from a
:class:`~pmnav_bt.webview.feed.Feed` of tree-log records: a log read whole (replay),
a log followed as a run writes it (``--follow``), or the lines a running tree writes
(``pmnav sim run --view``, the ROS node's ``view_port``). ``mapview.py`` gives the page
the building's annotated map and the map-to-pixel transform.
"""
