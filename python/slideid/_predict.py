"""Prediction in Python: predict (one push replayed with a friction), validate
(cross-validation over logs) and advise_push (which push next). Each returns the JSON
object its tool prints with --json, as a plain dict:
``slideid.predict(log, mu=0.3, b=1.2, c=0.035, mu_pusher=0.25)`` equals ``json.loads`` of
``predict --log ... --mu 0.3 --b 1.2 --c 0.035 --mu-pusher 0.25 --json``."""

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


def advise_push(**options):
    """Ranks candidate pushes by what each is expected to teach about the friction, with
    advise-push's options as keywords: patch (required), friction (identify's JSON file;
    without it the prior), mass, inertia, com_height, candidates (how many to return),
    criterion ("least-known" or "d-optimal"), mu_pusher, pose_noise, rate, contact_points,
    cone_fractions, lengths, tip_speed, tip_radius, prior_a, prior_b, prior_c, threads.
    Returns what advise-push --json prints: {"criterion", "known", "ranking": [...], ...}."""
    for key in ("friction",):
        if key in options and options[key] is not None:
            options[key] = os.fspath(options[key])
    return json.loads(_core.advise_push(**options))
