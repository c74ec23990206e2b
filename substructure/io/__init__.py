"""Files in and out of `substructure`: measured FRFs (CSV, UFF type 58) and more.

Submodules are imported on use (``from substructure.io.frf_files import
read_csv``), so that importing the package stays cheap and the core layers
never depend on file formats.
"""
