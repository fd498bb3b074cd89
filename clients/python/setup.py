"""setuptools hook of runout_client: generate the protobuf/gRPC modules while building.

pyproject.toml holds the package's metadata; this file only adds a build step. After the usual
build_py (which copies runout_client/*.py), generate_stubs.py writes runout_client/_proto into the
build folder from the service's .proto files (../../service/proto, or $RUNOUT_PROTO_DIR), with
Debian's protoc and grpc_python_plugin. So the wheel always matches the checkout it is built from,
and nothing generated lands in the source tree.
"""
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

sys.path.insert(0, str(Path(__file__).resolve().parent))
import generate_stubs  # noqa: E402  (beside this file)


class BuildPyWithStubs(build_py):
    """build_py, then the generated modules into the build (runout_client/_proto)."""

    def run(self):
        super().run()
        try:
            dest = generate_stubs.generate(self.build_lib)
        except generate_stubs.GenerateError as e:
            raise SystemExit(f"runout_client: cannot generate the gRPC modules: {e}") from None
        self.announce(f"generated {dest}", level=2)


setup(cmdclass={"build_py": BuildPyWithStubs})
