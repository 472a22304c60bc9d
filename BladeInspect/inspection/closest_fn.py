"""The ICP's closest-point function on the nominal, every call evaluated from scratch (the
exact distances; pipeline.TrackedDistance warm-starts them instead): the fits of
inspection.fitting run on it."""


def exact_closest_fn(nominal):
    def closest(points):
        res = nominal.signed_distance(points)
        return res.closest, res.normal, res.distance
    return closest
