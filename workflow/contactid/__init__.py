"""contactid: identification of frictional and normal contact forces at a
micro-vibro-impacting joint (Pourahmadian, Ahmadian & Jalali, J. Sound Vib. 2012).

The package holds the physics and numerics; it knows nothing of Snakemake.
"""

__version__ = "0.1.0"
