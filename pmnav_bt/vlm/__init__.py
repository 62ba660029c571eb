"""VLM back ends over an OpenAI-compatible chat API: the client, the H-CoT planning prompts,
answer parsing and validation against the priori-map, the planner and the coarse direction."""
