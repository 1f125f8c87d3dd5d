"""Studies: decks run along ladders of variants (mesh, integration, mass, technique,
time step), each run timed and checked against its references, and the report of error
against run time."""
