"""vampc: compile robot descriptions into programs for a network of VAMPs (Lathrop, Parallelism in
Manipulator Dynamics), emulate them, and report their cost."""
__version__ = "0.1.0"
