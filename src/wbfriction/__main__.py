"""``python -m wbfriction``: the command line, its signals handled first (:mod:`wbfriction.entry`)."""

from wbfriction.entry import main

if __name__ == "__main__":
    main()
