"""Speed and accuracy scripts; `people-tracker bench` builds on them."""
