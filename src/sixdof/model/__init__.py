"""What the system is: the rigid body, its mounts and the assembly of M, K and C.

:mod:`.system` holds the validated model objects, :mod:`.damping` the one damping matrix.
"""
