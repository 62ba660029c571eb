"""pmnav_bt.sim."""
