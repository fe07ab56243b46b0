"""The matplotlib import shared by every figure."""


def _pyplot():
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError(
            'skmotion.plotting needs matplotlib: pip install "skmotion[plot]"'
        ) from None
    return plt
