"""In a wheel, the repository's asm/, examples/ and sprites/ folders (setup.py maps them here, keeping
them side by side so the examples' relative paths to ../sprites hold). Empty in a clone."""
