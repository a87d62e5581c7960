"""One BLAS thread per process: our matrices are small, and every node and sweep worker is a
process of its own on a machine of few cores (OpenBLAS's threads only contend there). Set here,
before numpy is first imported by the node or command this package starts; an explicit
OPENBLAS_NUM_THREADS in the environment wins."""
import os

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
