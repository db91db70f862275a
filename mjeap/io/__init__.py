"""Input and output: files that survive a stop (outputs), users' CSV (csvio), Rerun recordings (recording)."""
