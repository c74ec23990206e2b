"""FRF files (internal): CSV and universal files (type 58), read and written.

The public names are in :mod:`substructure.io.frf_files` (and ``FRF.to_csv``, ``FRF.from_uff``,
...); the code is here, in the ``frf`` layer, so that the FRF's own methods read and write without
importing ``io`` (a higher layer).  The modules read into the class ``frf.response`` registers
(``_common.register_frf_class``) rather than importing it.
"""
