"""Solution, its archive format, linearisation, topology and resultants."""
