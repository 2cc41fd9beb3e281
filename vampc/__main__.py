"""`python -m vampc ...`: the `vampc` console script (vampc.launch), for a Python without it on the
PATH."""
from vampc.launch import main

if __name__ == "__main__":
    main()
