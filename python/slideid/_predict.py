"""Prediction in Python: predict (one push replayed with a friction) and validate
(cross-validation over logs). Both return the JSON object the tools print with --json, as a
plain dict: ``slideid.predict(log, mu=0.3, b=1.2, c=0.035, mu_pusher=0.25)`` equals
``json.loads`` of ``predict --log ... --mu 0.3 --b 1.2 --c 0.035 --mu-pusher 0.25 --json``."""

import json
import os

from . import _core
from ._log import Log


def _input(item):
    if isinstance(item, Log):
        return item._handle
    return os.fspath(item)


def predict(log, **options):
    """Predicts one push (a path or a Log) with predict's options as keywords: friction
    (identify's JSON file), mu, b, c, mu_pusher, drive ("pusher" or "force"), substeps,
    no_register_tip, out. Returns predict --json's object, with "predicted": the predicted
    trajectory as a Log."""
    out = _core.predict(_input(log), **options)
    result = json.loads(out["json"])
    result["predicted"] = Log(out["predicted"])
    return result


def validate(logs, **options):
    """Cross-validates over logs (paths, Logs, or a directory or glob as validate --logs
    takes) with validate's options as keywords: folds, leave_one_out, drive, mu_pusher,
    substeps, threads. Returns what validate --json writes."""
    if isinstance(logs, (str, os.PathLike)):
        logs = _core.log_files(os.fspath(logs))
    return json.loads(_core.validate([_input(item) for item in logs], **options))
