"""pmnav_bt.behaviours."""
