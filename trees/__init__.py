"""pmnav_bt.trees."""
