"""The plugin object QGIS holds: it registers the Processing provider and removes it again."""
from qgis.core import QgsApplication


class RunoutPlugin:
    def __init__(self, iface):
        self.iface = iface
        self.provider = None

    def initProcessing(self):  # noqa: N802 - QGIS's name
        """Called by QGIS (and by qgis_process, without initGui)."""
        if self.provider is None:
            from .provider import RunoutProvider
            self.provider = RunoutProvider()
            QgsApplication.processingRegistry().addProvider(self.provider)

    def initGui(self):  # noqa: N802 - QGIS's name
        self.initProcessing()

    def unload(self):
        if self.provider is not None:
            QgsApplication.processingRegistry().removeProvider(self.provider)
            self.provider = None
