"""Plans and planners: the plan data, the graph planner, resolving names and poses."""
