"""FeaturePython document objects. No GUI imports here."""
