#!/bin/bash
# The OpenFOAM side of the B1 tan-37 comparison: variants of the reference's b1rg_phi37 (fixed mesh,
# gravity turning; shared/reference/openfoam), each to 3 s. Run in a writable copy of the reference
# folder after its setup.sh (REF, default /work/of-ref); then CASE/Allrun one at a time and
#   bench/b1_tan37/b1_measure.py openfoam REF/CASE
# Builds interRotGTFoam (interRotGFoam with the transpose part of the viscous stress selectable by
# controlDict's transposeForm: interFoam, linearMu, harmonicMu, off) from openfoam-interRotGTFoam-UEqn.patch.
set -e
HERE=$(cd "$(dirname "$0")" && pwd)
REF=${REF:-/work/of-ref}
cd "$REF"
set +e; source ./env.sh >/dev/null 2>&1; set -e
if [ ! -x bin/interRotGTFoam ]; then
  rm -rf build/interRotGTFoam && cp -r build/interRotGFoam build/interRotGTFoam
  (cd build/interRotGTFoam && rm -rf Make/linux64* && mv interRotGFoam.C interRotGTFoam.C \
     && sed -i 's/interRotGFoam/interRotGTFoam/g' Make/files && patch -p1 UEqn.H < "$HERE/openfoam-interRotGTFoam-UEqn.patch" && wmake)
fi
mk() { rm -rf "$1"; cp -r b1rg_phi37 "$1"; sed -i "s/^endTime .*/endTime         3.0;/" "$1/system/controlDict"; }
conv() { sed -i "s/div(rhoPhi,U)   Gauss linearUpwind grad(U);/div(rhoPhi,U)   Gauss $2;/" "$1/system/fvSchemes"; }
mesh() {  # CASE N: N x N cells, filled to 0.110 m by volume
  sed -i "s/(50 50 1)/($2 $2 1)/" "$1/system/blockMeshDict"
  python3 - "$1" "$2" <<'PY'
import sys
d, n = sys.argv[1], int(sys.argv[2]); h = 0.2 / n; k = int(0.110 / h + 1e-9); frac = (0.110 - k * h) / h
s = open(d + "/system/setFieldsDict").read(); s = s[:s.index("regions")]
s += "regions\n(\n    boxToCell { box (-1 -1 -1) (1 %.6g 1); fieldValues ( volScalarFieldValue alpha.granular 1 ); }\n" % (k * h)
if frac > 1e-9:
    s += "    boxToCell { box (-1 %.6g -1) (1 %.6g 1); fieldValues ( volScalarFieldValue alpha.granular %.6g ); }\n" % (k * h, (k + 1) * h, frac)
s += ");\n"
open(d + "/system/setFieldsDict", "w").write(s)
PY
}
mk rg37_base
mk rg37_upwind;  conv rg37_upwind "upwind"
mk rg37_limlin;  conv rg37_limlin "limitedLinearV 1"
for f in interFoam linearMu harmonicMu off; do
  mk rg37_T$f
  sed -i "s/^application .*/application     interRotGTFoam;\ntransposeForm   $f;/" rg37_T$f/system/controlDict
  sed -i 's|../bin/interRotGFoam|../bin/interRotGTFoam|' rg37_T$f/Allrun
done
mk rg37_8mm_lu; mesh rg37_8mm_lu 25
mk rg37_8mm_up; mesh rg37_8mm_up 25; conv rg37_8mm_up "upwind"
mk rg37_2mm;    mesh rg37_2mm 100
