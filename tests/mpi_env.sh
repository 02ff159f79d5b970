# SPDX-License-Identifier: Apache-2.0
# Sourced by the MPI integration tests: lets Open MPI run as root (CI runs as root) and keeps
# ranks on this machine without binding, so several ranks share the 2 cores of CI.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_hwloc_base_binding_policy=none
export OMPI_MCA_btl_vader_single_copy_mechanism=none
mpirun_n() { local n=$1; shift; "$MPIEXEC" --oversubscribe -n "$n" "$@"; }
