"""What comes in and goes out as text: scenarios, the MCS link's three files and its watcher,
the check of a whole layout every reader shares, and the reports of a scan."""
