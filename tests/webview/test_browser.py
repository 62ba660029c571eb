"""The web view in a real browser (headless Chromium over the DevTools pipe): load a
recorded log of a failed run, check each node's status and the estimated pose shown
against the log, step a tick and jump to a failure, take a screenshot."""

from __future__ import annotations

from pathlib import Path

import pytest
from chromium import EXE, SKIP_REASON, Chromium

from pmnav_bt.treelog import read_tree_log
from pmnav_bt.webview.feed import Feed
from pmnav_bt.webview.server import ViewServer

pytestmark = pytest.mark.skipif(EXE is None, reason=SKIP_REASON)

LOG = Path(__file__).parent / "data" / "v2_fig2_room17_failed.tree.jsonl"
STATES = """[...document.querySelectorAll('#tree li')].map(
    (li) => [S.nodes[Number(li.dataset.node)].id, li.dataset.status])"""
SHOWN = """({tick: Number(document.getElementById('ticklabel').dataset.tick),
    x: document.getElementById('pose').dataset.x, y: document.getElementById('pose').dataset.y,
    failure: document.getElementById('knows').textContent})"""


def expected(ticks: list[dict], j: int) -> tuple[dict, list | None]:
    """Tick ``j``'s statuses and the pose the log holds then (the last one written)."""
    pose = next((t["view"]["pose"] for t in ticks[j::-1] if "pose" in t["view"]), None)
    return ticks[j]["status"], pose


def check(page, ticks: list[dict], j: int) -> dict:
    shown = page.eval(SHOWN)
    assert shown["tick"] == ticks[j]["tick"]
    status, pose = expected(ticks, j)
    assert {k: v for k, v in page.eval(STATES) if v} == status
    assert [float(shown["x"]), float(shown["y"])] == pytest.approx(pose[:2])
    return shown


def test_the_page_shows_the_log_and_steps_through_it(tmp_path):
    ticks = read_tree_log(LOG).ticks
    start = next(j for j, t in enumerate(ticks) if t["tick"] >= 1000)
    server = ViewServer(Feed(str(LOG), live=False).load(LOG)).start()
    browser = Chromium(tmp_path / "profile")
    try:
        page = browser.page(f"{server.url}?tick={ticks[start]['tick']}")
        page.wait_for("document.getElementById('ticklabel').dataset.tick !== '' && S.map !== null")
        check(page, ticks, start)
        page.click("step")
        check(page, ticks, start + 1)
        page.click("nextfail")
        shown = page.eval(SHOWN)
        j = next(k for k, t in enumerate(ticks) if t["tick"] == shown["tick"])
        assert j > start + 1 and ticks[j]["view"].get("failure")
        check(page, ticks, j)
        code = ticks[j]["view"]["failure"]["code"]
        assert f"last failure{code}: " in shown["failure"]
        page.wait_for("[...document.querySelectorAll('#found div')].length > 0")
        shot = page.screenshot(tmp_path / "view.png")
    finally:
        browser.close()
        server.close()
    assert shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and shot.stat().st_size > 50_000
