"""The paper's section 4.3 reproduced: its sweeps, atlas, figures, valid range, report and stress catalogue (the friction drive)."""
