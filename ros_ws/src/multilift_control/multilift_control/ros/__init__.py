"""One BLAS thread per process: our matrices are small, and every node and sweep worker is a
process of its own on a machine of few cores (OpenBLAS's threads only contend there). Set here,
before numpy is first imported by the node or command this package starts; an explicit
OPENBLAS_NUM_THREADS in the environment wins. Likewise plain reference counts for the
kernels' arrays (`multilift_sim.kernels.plain_reference_counts`: a node runs its kernels from
one thread)."""
import os

from multilift_sim.kernels import PLAIN_COUNTS

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
os.environ.setdefault(PLAIN_COUNTS, '1')
