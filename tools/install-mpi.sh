#!/usr/bin/env bash
# Installs covcontact's "mpi" extra (distributed runs on PETSc): Debian's MPI, MUMPS, ScaLAPACK, SuiteSparse
# and BLAS/LAPACK (when run as root on Debian), then PETSc and petsc4py built from source against them, then
# covcontact with the extra. The two source builds take 10 to 25 minutes on 2 cores; pip keeps the wheels
# in its cache, so a second install on the same machine takes seconds.
#
#     bash tools/install-mpi.sh            # from the repository root
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python}
if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq gfortran openmpi-bin libopenmpi-dev libmumps-dev libscalapack-openmpi-dev \
    libsuitesparse-dev liblapack-dev libblas-dev libopenblas-dev >/dev/null
fi
# PETSc's own downloads are not used: it links Debian's libraries.
export PETSC_CONFIGURE_OPTIONS="--with-fortran-bindings=0 --with-debugging=0 \
--with-mumps-include=/usr/include --with-mumps-lib=[-ldmumps,-lmumps_common,-lpord] \
--with-scalapack-lib=-lscalapack-openmpi \
--with-suitesparse-include=/usr/include/suitesparse \
--with-suitesparse-lib=[-lspqr,-lumfpack,-lklu,-lcholmod,-lbtf,-lccolamd,-lcolamd,-lcamd,-lamd,-lsuitesparseconfig] \
--with-blaslapack-lib=[-llapack,-lblas]"
"$PY" -m pip install "petsc==3.26.1"
# PETSC_DIR keeps petsc4py from building PETSc a second time
PETSC_DIR=$("$PY" -c "import petsc; print(petsc.get_petsc_dir())") PETSC_ARCH='' \
  "$PY" -m pip install "petsc4py==3.26.1"
"$PY" -m pip install ".[mpi]"
"$PY" -c "from petsc4py import PETSc; from mpi4py import MPI; print('PETSc', PETSc.Sys.getVersion(), MPI.Get_library_version().splitlines()[0])"
