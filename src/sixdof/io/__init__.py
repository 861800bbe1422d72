"""Files and text: scenario files in, HDF5 results and text tables out."""
