"""pmnav_bt.hardware."""
