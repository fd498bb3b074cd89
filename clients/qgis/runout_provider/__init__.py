"""runout's QGIS plugin: a Processing provider (id ``runout``) that runs runout scenarios.

QGIS calls :func:`classFactory` with its interface (``None`` in qgis_process, which then calls
``initProcessing`` only).
"""


def classFactory(iface):  # noqa: N802 - QGIS's name
    from .plugin import RunoutPlugin
    return RunoutPlugin(iface)
