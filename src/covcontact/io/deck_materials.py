"""A deck's material cards (*ELASTIC, *DENSITY, *PLASTIC, *HYPERELASTIC): the part of the deck reader
(:class:`covcontact.io.deck_model._Reader`) that fills the current *MATERIAL's entry, as a mixin of the reader
(it reads the reader's ``material`` and writes into its model ``m``; docs/input.md, "Abaqus and CalculiX decks")."""

from __future__ import annotations

from .deck import Card
from .deck_testdata import is_test_data_input, start_test_data


class MaterialCards:
    """The material methods of the deck reader."""

    def _material(self, c: Card) -> None:
        if self.material is None:
            raise c.fail("comes before any *MATERIAL")
        mat = self.m.materials[self.material]
        rows = c.rows()
        if not rows:
            raise c.fail("needs a data line")
        if c.name == "ELASTIC":
            # (CalculiX reads the type by its first letters: TYPE=ISO and Abaqus's TYPE=ISOTROPIC are both isotropic)
            if not "".join(c.param("TYPE", "ISO").upper().split()).startswith("ISO"):
                mat["unsupported"] = (f"{c.where()}: *ELASTIC, TYPE={c.params['TYPE']} is not supported (only "
                                      f"isotropic elasticity)")
                return
            temps = sorted({c.number(k, 2, r, "the temperature", 0.0) for k, r in enumerate(rows)})
            if len(rows) > 1 and len(temps) > 1:
                self.m.unsupported.append(f"{c.where()}: *ELASTIC: temperature-dependent elasticity ({len(temps)} "
                                          f"temperatures) is not supported; with --ignore-unsupported the first "
                                          f"line's values are used")
            elif len(rows) > 1:
                raise c.fail("isotropic elasticity is one line 'E, nu[, temperature]'; several lines need different "
                             "temperatures", 1)
            mat["E"] = c.number(0, 0, rows[0], "Young's modulus")
            mat["nu"] = c.number(0, 1, rows[0], "Poisson's ratio")
        elif c.name == "DENSITY":
            mat["density"] = c.number(0, 0, rows[0], "the density")
        else:
            hardening = c.param("HARDENING", "ISOTROPIC").upper()
            if hardening not in ("ISOTROPIC", "KINEMATIC"):
                self.m.unsupported.append(f"{c.where()}: *PLASTIC, HARDENING={c.params['HARDENING']} is not supported "
                                          f"(isotropic hardening, and linear kinematic hardening)")
                return
            temp = [c.number(k, 2, r, "the temperature", 0.0) for k, r in enumerate(rows)]
            if len(set(temp)) > 1:  # (a table at one temperature is not temperature-dependent)
                self.m.unsupported.append(f"{c.where()}: *PLASTIC: temperature-dependent hardening ({len(set(temp))} "
                                          f"temperatures) is not supported; with --ignore-unsupported the table at "
                                          f"the first temperature, {temp[0]:g}, is used")
            pts = [(c.number(k, 0, r, "the yield stress"), c.number(k, 1, r, "the plastic strain", 0.0))
                   for k, r in enumerate(rows) if temp[k] == temp[0]]
            if hardening == "KINEMATIC":  # (covcontact's kinematic hardening is linear: two points)
                if len(pts) != 2 or pts[0][1] != 0.0 or pts[1][1] <= 0.0:
                    self.m.unsupported.append(f"{c.where()}: *PLASTIC, HARDENING=KINEMATIC with other than two points "
                                              f"(0 and a positive plastic strain): kinematic hardening is linear")
                    return
                mat["kinematic"] = (pts[0][0], (pts[1][0] - pts[0][0]) / pts[1][1])
                return
            mat["plastic"] = pts

    def _hyperelastic(self, c: Card) -> None:
        """*HYPERELASTIC, <model>, N=: the rubber models (covcontact.materials.rubber) with CalculiX's data-line order
        (Abaqus's, eight values a line): ARRUDA-BOYCE mu, lambda_m, D; MOONEY-RIVLIN C10, C01, D1; NEO HOOKE C10, D1;
        OGDEN mu_1, alpha_1, ..., mu_N, alpha_N, D_1..D_N; POLYNOMIAL C10, C01, C20, C11, C02, C30, ..., D_1..D_N;
        REDUCED POLYNOMIAL C10, C20, ..., D_1..D_N; YEOH C10, C20, C30, D1, D2, D3 (no model: POLYNOMIAL, N=1). A
        compressibility of 0 is replaced as CalculiX replaces it: D_i = (0.1 / mu)^i (an initial Poisson's ratio of
        0.475), said in a note."""
        if self.material is None:
            raise c.fail("comes before any *MATERIAL")
        mat = self.m.materials[self.material]
        models = [m for m in (rubber_option(p) for p in c.params) if m is not None]
        if len(models) > 1:
            raise c.fail(f"names {len(models)} models; give one of ARRUDA-BOYCE, MOONEY-RIVLIN, NEO HOOKE, OGDEN, "
                         f"POLYNOMIAL, REDUCED POLYNOMIAL, YEOH")
        model = models[0] if models else "polynomial"
        if model == "van-der-waals":
            mat["unsupported"] = f"{c.where()}: *HYPERELASTIC, VAN DER WAALS is not supported"
            return
        n_text = c.param("N", "1")
        if not n_text.isdigit() or not 1 <= int(n_text):
            raise c.fail(f"N={n_text}: the order is a whole number from 1 to 6")
        N = int(n_text)
        if model not in ("ogden", "polynomial", "reduced-polynomial") and N != 1:
            raise c.fail(f"N={N} is for OGDEN, POLYNOMIAL and REDUCED POLYNOMIAL")
        if N > 6:
            raise c.fail(f"N={N}: the order is at most 6")
        if is_test_data_input(c):  # (constants fitted to *UNIAXIAL, *BIAXIAL, *PLANAR TEST DATA: deck_testdata)
            start_test_data(self, c, mat, model, N)
            return
        if "POISSON" in c.params:
            raise c.fail("POISSON= sets the compressibility of constants fitted to test data (TEST DATA INPUT); with "
                         "the constants on the data line give D1 there")
        rows = c.rows()
        if not rows:
            raise c.fail("needs a data line")
        if model == "polynomial":
            names = [f"c{n - j}{j}" for n in range(1, N + 1) for j in range(n + 1)]
        elif model == "reduced-polynomial":
            names = [f"c{n}0" for n in range(1, N + 1)]
        elif model == "ogden":
            names = [f"{k}{p}" for p in range(1, N + 1) for k in ("mu", "alpha")]
        else:
            names = {"arruda-boyce": ["mu", "lambda_m"], "mooney-rivlin": ["c10", "c01"], "neo-hooke": ["c10"],
                     "yeoh": ["c10", "c20", "c30"]}[model]
        nd = 3 if model == "yeoh" else N
        need = len(names) + nd
        per = -(-(need + 1) // 8)  # data lines of one temperature (eight values a line)
        if len(rows) > per:
            self.m.unsupported.append(f"{c.where()}: *HYPERELASTIC: temperature-dependent hyperelasticity "
                                      f"({-(-len(rows) // per)} temperatures) is not supported; with "
                                      f"--ignore-unsupported the first temperature's constants are used")
        values = []
        for k, row in enumerate(rows[:per]):
            for j in range(8 if k < per - 1 else need - len(values)):
                values.append(c.number(k, j, row, f"constant {len(values) + 1}", 0.0))
        const = dict(zip(names, values[:len(names)]))
        D = values[len(names):need]
        if model == "arruda-boyce":
            um = const["mu"]
        elif model == "ogden":
            um = sum(const[f"mu{p}"] for p in range(1, N + 1))
        else:
            um = 2.0 * (const.get("c10", 0.0) + const.get("c01", 0.0))
        for i in range(min(len(D), 3)):  # (CalculiX replaces its first three compressibilities)
            if abs(D[i]) < 1e-10 and um > 0.0:
                D[i] = (0.1 / um) ** (i + 1)
                mat.setdefault("notes", []).append(
                    f"{c.where()}: *HYPERELASTIC: the compressibility D{i + 1} = 0 is replaced by CalculiX's default "
                    f"(0.1 / mu0)^{i + 1} = {D[i]:.6g} (an initial Poisson's ratio of 0.475)")
        out: dict = {"model": model}
        if model == "ogden":
            out.update({"mu": [const[f"mu{p}"] for p in range(1, N + 1)],
                        "alpha": [const[f"alpha{p}"] for p in range(1, N + 1)], "d": D})
        elif model == "arruda-boyce":
            out.update({"mu": const["mu"], "lambda_m": const["lambda_m"], "d": D[0]})
        else:
            out.update({k: v for k, v in const.items() if v != 0.0 or k == "c10"})
            out.update({f"d{i + 1}": v for i, v in enumerate(D)})
            if model in ("polynomial", "reduced-polynomial"):
                out["n"] = N
        from ..materials.rubber import RubberError, rubber_from_keys

        try:  # (the constants checked at the card; E0, the initial Young's modulus, for the contact defaults)
            keys = {k: v for k, v in out.items() if k != "model"}
            mat["E0"] = rubber_from_keys(model, keys).E
        except RubberError as exc:
            raise c.fail(f"{exc.key}: {exc}" if exc.key else str(exc)) from None
        mat["hyperelastic"] = out
        mat["hyperelastic_where"] = c.where()


def rubber_option(param: str) -> str | None:
    """The rubber model a *HYPERELASTIC parameter names (CalculiX drops the blanks: NEO HOOKE is NEOHOOKE), or None."""
    key = param.upper().replace(" ", "").replace("_", "")
    return {"ARRUDA-BOYCE": "arruda-boyce", "MOONEY-RIVLIN": "mooney-rivlin", "NEOHOOKE": "neo-hooke",
            "OGDEN": "ogden", "POLYNOMIAL": "polynomial", "REDUCEDPOLYNOMIAL": "reduced-polynomial", "YEOH": "yeoh",
            "VANDERWAALS": "van-der-waals"}.get(key)
