"""summary.json's text with each step's record encoded once (io.observers.Summary.text): the same text as encoding
the whole summary anew, after every step of a run and after a resume from a checkpoint's copy."""

from __future__ import annotations

import json

import numpy as np

from covcontact.io.observers import Summary
from covcontact.io.output import summary_text


def test_cached_records_give_the_whole_encoding():
    s = Summary(None)
    s.data = {"problem": "p", "status": "running", "total_iterations": 0, "wall_time_s": 0.0, "steps": []}
    for k in range(1, 6):
        s.data["steps"].append({"step": k, "iterations": np.int64(k + 2), "force": np.array([0.5 * k, -1.0]),
                                "converged": bool(k % 2)})
        s.data["total_iterations"] += k + 2
        assert s.text() == summary_text(s.data)
        s.data["steps"][-1]["late"] = k  # the last record may still change until the next step comes
        assert s.text() == summary_text(s.data)
    assert len(s._steps) == 4  # the earlier records, encoded once
    _, meta = s.checkpoint()
    r = Summary(None)
    r.restore({}, json.loads(json.dumps(meta)))
    assert r.data == json.loads(summary_text(s.data)) and r.text() == summary_text(s.data)
    old = Summary(None)  # a checkpoint written before the text: the summary itself
    old.restore({}, {"summary": json.loads(summary_text(s.data)), "wall_time_s": 1.0})
    assert old.text() == summary_text(s.data) and old.t_before == 1.0
