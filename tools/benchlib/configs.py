"""Configurations: the ways of rendering a scene (backend × emission estimator ×
majorant, and the BSDF/phase-sampling-only variants); --configs filters on
their names."""


class Config:
    """One way of rendering a scene. `name` is what --configs filters on."""

    def __init__(self, backend, estimator=None, majorant=None, mis=None):
        self.backend = backend
        self.estimator = estimator   # None: the scene has no grid media, the keys do nothing
        self.majorant = majorant
        self.mis = mis               # None: the scene's own integrator.mis; False: BSDF/phase sampling only
        if estimator is None:
            self.name = backend
        elif backend == "cpu":
            # The CPU reference always tracks with one global majorant (docs/benchmarks.md).
            self.name = f"cpu/{estimator}"
        else:
            self.name = f"{backend}/{estimator}/{majorant}"
        if mis is False:
            self.name += "/bsdf-only"

    @property
    def slug(self):
        return self.name.replace("/", "-")

    def csv_fields(self):
        return {
            "config": self.name, "backend": self.backend,
            "estimator": self.estimator or "absorption (homogeneous)",
            "majorant": "n/a" if self.estimator is None else self.majorant,
            # The bench writes the light strategy the render reports instead
            # (its --stats): "scene" did not say whether lights were sampled.
            "mis": "off" if self.mis is False else "scene",
        }


def configs_for(scene, quick):
    """The configurations that differ for this scene.

    Homogeneous-only scenes ignore estimator and majorant (homogeneous media always
    use the absorption estimator, and the majorant grid is a grid-media feature),
    so they get one config per backend. Where the scene's collision configs use
    next-event estimation + MIS (docs/mis.md: lights to sample and something
    that scatters), "…/bsdf-only" configs render the same with integrator.mis
    off, for the comparison.
    """
    if not scene.has_grid:
        return [Config("vulkan"), Config("cpu")]
    out = [Config("vulkan", e, m) for e in ("absorption", "collision") for m in ("grid", "global")]
    # Further estimators a scene asks for ("line", "auto": its default) with the majorant grid.
    out += [Config("vulkan", e, "grid") for e in scene.estimators if e not in ("absorption", "collision")]
    # The CPU reference is 2–5× slower: quick mode runs it with one estimator only.
    cpu_estimators = ("collision",) if quick else ("absorption", "collision")
    out += [Config("cpu", e, "global") for e in cpu_estimators]
    if scene.uses_mis:
        out += [Config("vulkan", "collision", "grid", mis=False), Config("cpu", "collision", "global", mis=False)]
    return out
