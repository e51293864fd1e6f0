"""What the virtual tests' checks read off a load curve."""


def increments(result):
    """(x, y) of a VirtualTestResult's curve, each from its first point
    (the released or settled sample)."""
    x, y = result.curve.arrays()
    return x - x[0], y - y[0]
