"""What the system is: the rigid body, its mounts and the assembly of M, K and C.

:mod:`.parts` holds the validated body, mounts and Maxwell branches, :mod:`.system` the system they make and its
matrices, :mod:`.damping` the one damping matrix.
"""
