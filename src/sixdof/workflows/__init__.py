"""One module per command's computation: each computes typed results without files, and saves them apart."""
