"""MuJoCo hardware abstraction."""
