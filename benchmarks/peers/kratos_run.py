"""Solve a case written by kratos_deck.py with Kratos Multiphysics and write the per-step results as JSON.

Run with the Python that has Kratos installed (not covcontact's; this file imports neither covcontact nor
anything outside Kratos and the standard library):

    <kratos python> kratos_run.py CASE_FOLDER [--threads N] [--out results.json] [--probe]

It drives Kratos's own ``StructuralMechanicsAnalysis`` (the solver, strategy and processes it builds from
ProjectParameters.json), with a solution loop that records after every step: the time, the Newton
iterations (``NL_ITERATION_NUMBER``), whether the step converged, and the total REACTION of every
sub-model-part listed under ``race.report`` in the parameters. The per-node penalties under
``race.nodal_penalty`` (Kratos node id: eps) replace the contact process's global INITIAL_PENALTY after
initialisation. ``--probe`` adds, per step, the contact
quantities of the contact nodes (positions, weighted gap, pressure, nodal area, flags) used to check the penalty's meaning.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

T0 = time.perf_counter()

import KratosMultiphysics as KM
import KratosMultiphysics.ConstitutiveLawsApplication
import KratosMultiphysics.ContactStructuralMechanicsApplication as CSMA
import KratosMultiphysics.LinearSolversApplication
from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import (
    StructuralMechanicsAnalysis,
)


class RaceAnalysis(StructuralMechanicsAnalysis):
    """Kratos's structural analysis with a solution loop that records reactions and iterations per step."""

    def __init__(self, model, parameters, report, nodal_penalty=None, probe=False):
        super().__init__(model, parameters)
        self.report = report
        self.nodal_penalty = nodal_penalty or {}
        self.probe = probe
        self.records = []

    def Initialize(self):
        super().Initialize()
        # the contact process has set every node's INITIAL_PENALTY to the global value; set the per-node ones
        main = self.model["Structure"]
        for key, eps in self.nodal_penalty.items():
            main.GetNode(int(key)).SetValue(KM.INITIAL_PENALTY, eps)

    def RunSolutionLoop(self):
        while self.KeepAdvancingSolutionLoop():
            self.time = self._AdvanceTime()
            self.InitializeSolutionStep()
            self._GetSolver().Predict()
            converged = self._GetSolver().SolveSolutionStep()
            self.FinalizeSolutionStep()
            self.OutputSolutionStep()
            self.records.append(self._record(bool(converged)))

    def _record(self, converged):
        mp = self._GetSolver().GetComputingModelPart()
        rec = {"time": self.time, "converged": converged,
               "iterations": int(mp.ProcessInfo[KM.NL_ITERATION_NUMBER]), "reaction": {}}
        for name in self.report:
            r = [0.0, 0.0, 0.0]
            for node in self.model[name].Nodes:
                v = node.GetSolutionStepValue(KM.REACTION)
                r = [r[0] + v[0], r[1] + v[1], r[2] + v[2]]
            rec["reaction"][name] = r
        if self.probe:
            main = self.model["Structure"]
            rows = []
            for node in main.GetSubModelPart("Contact").Nodes:
                rows.append([node.Id, node.X0, node.Y0, node.Z0, node.X, node.Y, node.Z,
                             node.GetSolutionStepValue(CSMA.WEIGHTED_GAP),
                             node.GetValue(CSMA.AUGMENTED_NORMAL_CONTACT_PRESSURE),
                             node.GetValue(KM.NODAL_AREA) if node.Has(KM.NODAL_AREA) else None,
                             node.GetValue(KM.INITIAL_PENALTY) if node.Has(KM.INITIAL_PENALTY) else None,
                             bool(node.Is(KM.ACTIVE)), bool(node.Is(KM.SLAVE))])
            rec["contact_nodes"] = rows
        return rec


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("case", help="folder with ProjectParameters.json, mesh.mdpa, materials.json")
    ap.add_argument("--threads", type=int, default=0, help="OpenMP threads (default: Kratos's own choice)")
    ap.add_argument("--out", default="results.json", help="JSON file, relative to the case folder")
    ap.add_argument("--probe", action="store_true", help="also record the slave nodes' contact quantities")
    ap.add_argument("--verbose", action="store_true", help="keep Kratos's info messages")
    args = ap.parse_args(argv)
    os.chdir(args.case)
    if args.threads > 0:
        KM.ParallelUtilities.SetNumThreads(args.threads)
    if not args.verbose:
        KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    with open("ProjectParameters.json") as f:
        raw = json.load(f)
    race = raw.pop("race", {})
    report = race.get("report", [])
    params = KM.Parameters(json.dumps(raw))
    model = KM.Model()
    t1 = time.perf_counter()
    analysis = RaceAnalysis(model, params, report, race.get("nodal_penalty"), probe=args.probe)
    analysis.Run()
    t2 = time.perf_counter()
    out = {"kratos_version": KM.KratosGlobals.Kernel.Version() if hasattr(KM.KratosGlobals, "Kernel") else "",
           "threads": KM.ParallelUtilities.GetNumThreads(), "import_s": round(t1 - T0, 3),
           "analysis_s": round(t2 - t1, 3), "steps": analysis.records,
           "converged": bool(analysis.records) and all(r["converged"] for r in analysis.records),
           "total_iterations": sum(r["iterations"] for r in analysis.records)}
    with open(args.out, "w") as f:
        json.dump(out, f)
    return 0 if out["converged"] else 1


if __name__ == "__main__":
    sys.exit(main())
