"""The Processing provider ``runout``: its algorithms are ``runout:run`` and ``runout:run_file``."""
import os

from qgis.core import QgsProcessingProvider
from qgis.PyQt.QtGui import QIcon

from .algorithms import RunScenarioAlgorithm, RunScenarioFileAlgorithm

_ICON = os.path.join(os.path.dirname(__file__), "icon.svg")


class RunoutProvider(QgsProcessingProvider):
    def id(self):
        return "runout"

    def name(self):
        return "runout"

    def longName(self):  # noqa: N802 - QGIS's name
        return "runout: hazard maps of rapid granular flows"

    def icon(self):
        return QIcon(_ICON) if os.path.isfile(_ICON) else QgsProcessingProvider.icon(self)

    def svgIconPath(self):  # noqa: N802 - QGIS's name
        return _ICON if os.path.isfile(_ICON) else QgsProcessingProvider.svgIconPath(self)

    def loadAlgorithms(self):  # noqa: N802 - QGIS's name
        self.addAlgorithm(RunScenarioAlgorithm())
        self.addAlgorithm(RunScenarioFileAlgorithm())
