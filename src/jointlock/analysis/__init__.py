"""Analysis of an arm's state: kinematic ability indices, singularities, workspace."""
